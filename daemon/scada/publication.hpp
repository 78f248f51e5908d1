#pragma once

#include <nlohmann/json.hpp>

namespace icewatch::daemon::scada {

// What the service loop tells the SCADA interfaces each time it writes latest.json.
struct Publication {
    nlohmann::json document;    // exactly the latest.json document
    bool newResult = true;      // false: the same result with its alarm changed (a reset)
    bool alarmLatched = false;  // the alarm is held by alarm.latch until a reset
};

// Receives publications on the service loop's thread. Implementations hand the document to their
// own threads and return at once: they never block, and never call back into the daemon (the loop
// may hold its own lock while it calls).
class PublicationSink {
public:
    virtual ~PublicationSink() = default;
    virtual void published(const Publication& publication) = 0;
};

}  // namespace icewatch::daemon::scada
