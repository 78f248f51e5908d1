// The state directory: latest.json, history.sqlite, baseline/, images/ and the lock.
#include "daemon/state_dir.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/common/error.hpp"
#include "daemon/atomic_file.hpp"

namespace icewatch::daemon {

void prepareStateDir(const std::filesystem::path& dir) {
    for (const auto& sub : {dir, dir / "images", dir / "baseline"}) {
        std::error_code ec;
        std::filesystem::create_directories(sub, ec);
        if (ec || !std::filesystem::is_directory(sub)) {
            throw Error(kExitCantCreate, sub.string() + ": cannot create the state directory: " +
                                             (ec ? ec.message() : "not a directory"));
        }
        removeStaleTemporaries(sub);
    }
}

StateDirLock::StateDirLock(const std::filesystem::path& dir) {
    const auto path = dir / "lock";
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) {
        throw Error(kExitCantCreate, path.string() + ": cannot create the lock file: " + std::strerror(errno));
    }
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
        ::close(fd_);
        throw Error(kExitTempFail, dir.string() + ": in use by another icewatchd (or icewatch baseline capture)");
    }
}

StateDirLock::~StateDirLock() {
    ::close(fd_);
}

}  // namespace icewatch::daemon
