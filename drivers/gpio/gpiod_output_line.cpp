// libgpiod 1.6 v1 C++ binding (gpiod.hpp): the only place that knows it. Logical values are used
// throughout: with FLAG_ACTIVE_LOW the kernel inverts, so "energised" is 1 whatever the wiring.
#include "drivers/gpio/gpiod_output_line.hpp"

#include <system_error>

#include <gpiod.hpp>

#include "core/common/error.hpp"
#include "drivers/log/log.hpp"

namespace icewatch::gpio {

struct GpiodOutputLine::Impl {
    gpiod::chip chip;
    gpiod::line line;
    std::string name;
};

GpiodOutputLine::GpiodOutputLine(const std::string& chip, unsigned offset, bool activeLow,
                                 const std::string& consumer)
    : impl_(std::make_unique<Impl>()) {
    impl_->name = chip + " line " + std::to_string(offset);
    try {
        impl_->chip.open(chip, gpiod::chip::OPEN_LOOKUP);
        if (offset >= impl_->chip.num_lines()) {
            throw Error(kExitUnavailable, "gpio: " + chip + " has " + std::to_string(impl_->chip.num_lines()) +
                                              " lines, no line " + std::to_string(offset));
        }
        impl_->line = impl_->chip.get_line(offset);
        gpiod::line_request request;
        request.consumer = consumer;
        request.request_type = gpiod::line_request::DIRECTION_OUTPUT;
        if (activeLow) {
            request.flags = gpiod::line_request::FLAG_ACTIVE_LOW;
        }
        impl_->line.request(request, 0);
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(kExitUnavailable, "gpio: cannot request " + impl_->name + " as an output: " + e.what());
    }
}

GpiodOutputLine::~GpiodOutputLine() {
    // Leave the fail-safe level behind: the kernel keeps the last value after release.
    try {
        impl_->line.set_value(0);
        impl_->line.release();
    } catch (const std::exception& e) {
        log::get("gpio")->error("cannot de-energise {} on release: {}", impl_->name, e.what());
    }
}

bool GpiodOutputLine::set(bool energised) {
    try {
        impl_->line.set_value(energised ? 1 : 0);
    } catch (const std::exception& e) {
        log::get("gpio")->error("cannot drive {}: {}", impl_->name, e.what());
        return false;
    }
    energised_ = energised;
    return true;
}

}  // namespace icewatch::gpio
