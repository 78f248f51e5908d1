// The production side of the syscall seam: straight libc calls, errno turned into a return value.
#include <cerrno>

#include <fcntl.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include "drivers/v4l2/syscalls.hpp"

namespace icewatch::v4l2 {

int LibcSyscalls::open(const std::string& path, int flags) {
    const int fd = ::open(path.c_str(), flags);
    return fd < 0 ? -errno : fd;
}

int LibcSyscalls::close(int fd) { return ::close(fd) < 0 ? -errno : 0; }

int LibcSyscalls::ioctl(int fd, unsigned long request, void* arg) {
    const int result = ::ioctl(fd, request, arg);
    return result < 0 ? -errno : result;
}

void* LibcSyscalls::mmap(std::size_t length, int prot, int flags, int fd, off_t offset, int* error) {
    void* address = ::mmap(nullptr, length, prot, flags, fd, offset);
    if (address == MAP_FAILED) {
        *error = errno;
        return nullptr;
    }
    *error = 0;
    return address;
}

int LibcSyscalls::munmap(void* address, std::size_t length) { return ::munmap(address, length) < 0 ? -errno : 0; }

int LibcSyscalls::poll(pollfd* fds, nfds_t count, int timeoutMs) {
    const int result = ::poll(fds, count, timeoutMs);
    return result < 0 ? -errno : result;
}

}  // namespace icewatch::v4l2
