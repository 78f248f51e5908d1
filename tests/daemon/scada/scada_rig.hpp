#pragma once

// Real counterparts for the SCADA tests: a process (icewatchd, mosquitto), a mosquitto broker on
// a free loopback port, an MQTT subscriber and a Modbus client, both through the same libraries
// the daemon uses but through their client APIs. Every wait polls against a deadline.
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

struct mosquitto;
struct mosquitto_message;
struct _modbus;

namespace icewatch::daemon::scada::test {

using namespace std::chrono_literals;

constexpr auto kGuard = 20s;  // against a hang only: every wait ends as soon as its event comes

// Polls until done() or the guard runs out; true when done.
bool waitFor(const std::function<bool()>& done, std::chrono::milliseconds guard = kGuard);

// A port nothing listens on at the moment (the kernel's choice for a bind to port 0).
int freeLoopbackPort();

// A whole text file ("" when there is none), and how often what occurs in text.
std::string readText(const std::filesystem::path& path);
std::size_t occurrences(const std::string& text, const std::string& what);

// A child process, its stdout and stderr appended to log; killed if still running at the end.
class ChildProcess {
public:
    ChildProcess(const std::vector<std::string>& argv, const std::filesystem::path& log);
    ~ChildProcess();
    ChildProcess(const ChildProcess&) = delete;
    ChildProcess& operator=(const ChildProcess&) = delete;

    void signal(int s) const;
    // The exit status (128 + signal when killed), or -1 when it did not end within the guard.
    int awaitExit();
    bool running();

private:
    pid_t pid_ = -1;
};

// mosquitto on 127.0.0.1:port, anonymous, without persistence (a restart forgets everything);
// extraConfig is appended to its configuration (another listener, say).
class Broker {
public:
    explicit Broker(const std::filesystem::path& dir, const std::string& extraConfig = "");
    void start();  // on the same port every time; returns once it accepts connections
    void stop();   // SIGTERM, waits for the exit
    int port() const { return port_; }
    std::string url() const { return "mqtt://127.0.0.1:" + std::to_string(port_); }

private:
    std::filesystem::path dir_;
    int port_;
    std::optional<ChildProcess> process_;
};

// Subscribes to filter and keeps every message (retained ones included) in arrival order.
class Subscriber {
public:
    Subscriber(int port, const std::string& filter);
    ~Subscriber();
    Subscriber(const Subscriber&) = delete;
    Subscriber& operator=(const Subscriber&) = delete;

    // The first payload on topic, arrived from the start or after the first `skip` ones there,
    // that accept takes; nullopt when none did within the guard.
    std::optional<std::string> await(const std::string& topic,
                                     const std::function<bool(const std::string&)>& accept = {},
                                     std::size_t skip = 0);
    std::vector<std::string> payloads(const std::string& topic);

private:
    static void onMessage(mosquitto*, void* self, const mosquitto_message* message);
    mosquitto* client_ = nullptr;
    std::mutex mutex_;
    std::map<std::string, std::vector<std::string>> received_;
};

// libmodbus's client on 127.0.0.1:port.
class ModbusClient {
public:
    explicit ModbusClient(int port, int unit = 255);
    ~ModbusClient();
    ModbusClient(const ModbusClient&) = delete;
    ModbusClient& operator=(const ModbusClient&) = delete;

    // The values, or the errno libmodbus gave (EMBXILFUN, EMBXILADD, ...) as a negative count.
    std::vector<std::uint16_t> inputRegisters(int address, int count, int* error = nullptr);
    std::vector<std::uint8_t> discreteInputs(int address, int count, int* error = nullptr);
    // 0 or the errno of the exception.
    int writeCoil(int address, bool on);
    int readHoldingRegisters(int address, int count);
    _modbus* context() { return ctx_; }

private:
    _modbus* ctx_ = nullptr;
};

// A float32 of two registers, high word first (the map's encoding).
float floatAt(const std::vector<std::uint16_t>& registers, int address);
std::uint32_t uint32At(const std::vector<std::uint16_t>& registers, int address);

}  // namespace icewatch::daemon::scada::test
