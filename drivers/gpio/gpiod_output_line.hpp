#pragma once

#include <memory>
#include <string>

#include "drivers/gpio/output_line.hpp"

namespace icewatch::gpio {

// A GPIO output through libgpiod 1.6 (the character device, /dev/gpiochipN). The line is requested
// as an output, de-energised, with the active-low flag when the wiring needs it, and it is
// de-energised again and released by the destructor.
class GpiodOutputLine : public OutputLine {
public:
    // chip: a name (gpiochip0), a path (/dev/gpiochip0), a label or a number, as gpiod looks it
    // up. Throws Error(kExitUnavailable) naming chip and offset when the line cannot be had.
    GpiodOutputLine(const std::string& chip, unsigned offset, bool activeLow, const std::string& consumer);
    ~GpiodOutputLine() override;
    GpiodOutputLine(const GpiodOutputLine&) = delete;
    GpiodOutputLine& operator=(const GpiodOutputLine&) = delete;

    bool set(bool energised) override;
    bool energised() const override { return energised_; }

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    bool energised_ = false;
};

}  // namespace icewatch::gpio
