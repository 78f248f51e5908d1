// Atomic replacement of small state files (latest.json, the last pictures, the baseline record).
// rename(2) within one file system is atomic; the fsyncs make the new content and the new name
// survive a power cut in that order.
#include "daemon/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <string>

namespace icewatch::daemon {

namespace {
constexpr std::string_view kTempMarker = ".tmp.";

bool writeAll(int fd, std::string_view content) {
    std::size_t done = 0;
    while (done < content.size()) {
        const ssize_t n = ::write(fd, content.data() + done, content.size() - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            return false;
        }
        done += static_cast<std::size_t>(n);
    }
    return true;
}
}  // namespace

bool writeFileAtomically(const std::filesystem::path& path, std::string_view content, Durability durability) {
    const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
    std::string temp = (dir / (path.filename().string() + std::string(kTempMarker) + "XXXXXX")).string();
    const int fd = ::mkostemp(temp.data(), O_CLOEXEC);
    if (fd < 0) {
        return false;
    }
    const bool durable = durability == Durability::Durable;
    bool ok = ::fchmod(fd, 0644) == 0 && writeAll(fd, content) && (!durable || ::fsync(fd) == 0);
    const int savedErrno = errno;
    ok = ::close(fd) == 0 && ok;
    if (!ok || ::rename(temp.c_str(), path.c_str()) != 0) {
        const int e = ok ? errno : savedErrno;
        ::unlink(temp.c_str());
        errno = e;
        return false;
    }
    if (!durable) {
        return true;
    }
    const int dirFd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dirFd < 0) {
        return false;
    }
    const bool synced = ::fsync(dirFd) == 0;
    ::close(dirFd);
    return synced;
}

void removeStaleTemporaries(const std::filesystem::path& dir) {
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
        if (entry.path().filename().string().find(kTempMarker) != std::string::npos) {
            std::filesystem::remove(entry.path(), ec);
        }
    }
}

}  // namespace icewatch::daemon
