#pragma once

#include <cstddef>
#include <string>

#include <poll.h>
#include <sys/types.h>

namespace icewatch::v4l2 {

// The seam between the V4L2 driver code and the kernel: the six system calls capture needs. The
// production implementation (LibcSyscalls) calls libc; FakeUvcDevice answers like the kernel's
// uvcvideo so tests and the demo run the real driver code. Every call returns -errno on failure
// instead of setting errno, so nothing depends on thread-local state between call and check.
class Syscalls {
public:
    virtual ~Syscalls() = default;

    // A file descriptor (>= 0) or -errno.
    virtual int open(const std::string& path, int flags) = 0;
    // 0 or -errno.
    virtual int close(int fd) = 0;
    // The ioctl's non-negative result or -errno.
    virtual int ioctl(int fd, unsigned long request, void* arg) = 0;
    // The mapped address, or nullptr with *error set to errno.
    virtual void* mmap(std::size_t length, int prot, int flags, int fd, off_t offset, int* error) = 0;
    // 0 or -errno.
    virtual int munmap(void* address, std::size_t length) = 0;
    // The number of ready descriptors, 0 on timeout, or -errno.
    virtual int poll(pollfd* fds, nfds_t count, int timeoutMs) = 0;
};

// The real kernel.
class LibcSyscalls final : public Syscalls {
public:
    int open(const std::string& path, int flags) override;
    int close(int fd) override;
    int ioctl(int fd, unsigned long request, void* arg) override;
    void* mmap(std::size_t length, int prot, int flags, int fd, off_t offset, int* error) override;
    int munmap(void* address, std::size_t length) override;
    int poll(pollfd* fds, nfds_t count, int timeoutMs) override;
};

}  // namespace icewatch::v4l2
