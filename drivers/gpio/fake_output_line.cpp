// Fake GPIO lines: what SCADA would have seen, as a list of transitions a test can compare exactly.
#include "drivers/gpio/fake_output_line.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <fstream>

#include "drivers/log/log.hpp"

namespace icewatch::gpio {

void TransitionLog::record(const std::string& line, bool energised) {
    std::lock_guard lock(mutex_);
    transitions_.push_back({line, energised});
    if (file_.empty()) {
        return;
    }
    // One write(2) per transition with O_APPEND: a reader never sees half a line.
    const std::string text = line + (energised ? " 1\n" : " 0\n");
    const int fd = ::open(file_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd < 0 || ::write(fd, text.data(), text.size()) != static_cast<ssize_t>(text.size())) {
        log::get("gpio")->error("fake gpio: cannot append to {}", file_.string());
    }
    if (fd >= 0) {
        ::close(fd);
    }
}

std::vector<LineTransition> TransitionLog::transitions() const {
    std::lock_guard lock(mutex_);
    return transitions_;
}

std::vector<LineTransition> readTransitionFile(const std::filesystem::path& file) {
    std::vector<LineTransition> out;
    std::ifstream in(file);
    std::string line;
    int value = 0;
    while (in >> line >> value) {
        out.push_back({line, value != 0});
    }
    return out;
}

bool FakeOutputLine::set(bool energised) {
    if (energised != energised_) {
        energised_ = energised;
        log_->record(name_, energised);
    }
    return true;
}

}  // namespace icewatch::gpio
