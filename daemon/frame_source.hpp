#pragma once

#include <optional>
#include <string>

#include "core/common/side_by_side.hpp"

namespace icewatch::daemon {

enum class CameraState { Ok, Offline, Degraded };

const char* toString(CameraState state);

// Where the daemon's frames come from: the V4L2 camera in production, a recording through the fake
// V4L2 device in the demo and tests, a scripted double in unit tests. Called from the service loop
// only. Failures are return values with a reason a person can read; nothing here throws for a
// camera that is absent or misbehaving.
class FrameSource {
public:
    virtual ~FrameSource() = default;

    // Opens the camera, or does nothing when it is open. false + reason when it is not there.
    virtual bool open(std::string& error) = 0;
    // The freshest valid frame, split into eyes (left eye = left half). nullopt + reason when no
    // frame came (unplugged, stalled); the source then counts as offline until open() succeeds.
    virtual std::optional<StereoPair> grabFreshest(std::string& error) = 0;
    // Looked at every daemon.camera_check_s between cycles. May re-open a vanished camera on its
    // own schedule. Offline: not there; Degraded: there but dropping or substituting frames.
    virtual CameraState health(std::string& detail) = 0;
    // Releases the device (shutdown).
    virtual void close() = 0;
};

}  // namespace icewatch::daemon
