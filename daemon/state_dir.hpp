#pragma once

#include <filesystem>

namespace icewatch::daemon {

// Creates the state directory (and images/, baseline/) when missing and removes temporaries an
// interrupted write left. Throws Error(kExitCantCreate) naming the directory.
void prepareStateDir(const std::filesystem::path& dir);

// An exclusive lock on STATE_DIR/lock for as long as the object lives: one daemon (or one
// `icewatch baseline capture`) per state directory. Throws Error(kExitTempFail) when it is held.
class StateDirLock {
public:
    explicit StateDirLock(const std::filesystem::path& dir);
    ~StateDirLock();
    StateDirLock(const StateDirLock&) = delete;
    StateDirLock& operator=(const StateDirLock&) = delete;

private:
    int fd_ = -1;
};

}  // namespace icewatch::daemon
