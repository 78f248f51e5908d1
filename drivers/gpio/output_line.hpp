#pragma once

namespace icewatch::gpio {

// One digital output toward SCADA. "Energised" is the logical state (the relay pulled in); the
// implementation maps it to the electrical level (active-low wiring). A new line starts
// de-energised, which reads as fault/alarm: the fail-safe state.
class OutputLine {
public:
    virtual ~OutputLine() = default;

    // Returns false when the line could not be driven (the caller logs; the line's state is then
    // unknown and the next call tries again).
    virtual bool set(bool energised) = 0;
    virtual bool energised() const = 0;
};

}  // namespace icewatch::gpio
