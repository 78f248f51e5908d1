#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "core/config/scada_config.hpp"
#include "daemon/scada/register_map.hpp"

namespace icewatch::daemon::scada {

// What the server asks of the rest of the daemon, always from its own thread and never while it
// holds a lock of its own.
struct ModbusHooks {
    std::function<void()> measureNow;   // coil 0
    std::function<void()> resetAlarm;   // coil 1
    std::function<bool()> loopAlive;    // the heartbeat register counts only while this says so
    std::function<bool()> resultStale;  // discrete input 3
};

struct ModbusLimits {
    int maxClients = 16;                            // more connections are closed at once
    std::chrono::milliseconds idleTimeout{60000};   // a connection silent this long is closed
};

// The Modbus TCP server (libmodbus) of register_map.hpp. One thread serves every client, each
// request answered whole before the next is read, so one image serves a request and a slow or
// silent client can only cost itself its connection. The service loop hands over images with
// show(), which never waits on a client.
class ModbusServer {
public:
    // Listens at once; throws Error(kExitUnavailable) when it cannot.
    ModbusServer(const config::ModbusConfig& config, ModbusHooks hooks, ModbusLimits limits = {});
    // Closes every connection and joins.
    ~ModbusServer();
    ModbusServer(const ModbusServer&) = delete;
    ModbusServer& operator=(const ModbusServer&) = delete;

    int port() const { return port_; }
    // The registers of one result, replacing the previous ones in one step.
    void show(const RegisterImage& image);

private:
    struct Context;
    void serve();

    config::ModbusConfig config_;
    ModbusHooks hooks_;
    ModbusLimits limits_;
    std::unique_ptr<Context> context_;  // libmodbus state, the server thread's alone once it runs
    int port_ = 0;
    int wakeFd_ = -1;                   // eventfd: stop

    std::mutex mutex_;
    RegisterImage image_;               // guarded by mutex_
    std::uint64_t imageVersion_ = 0;    // guarded by mutex_: counts show() calls
    std::thread thread_;
};

}  // namespace icewatch::daemon::scada
