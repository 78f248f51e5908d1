#include "tests/daemon/scada/scada_rig.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <modbus.h>
#include <mosquitto.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace icewatch::daemon::scada::test {

namespace {

sockaddr_in loopback(int port) {
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<std::uint16_t>(port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    return address;
}

bool accepting(int port) {
    const int s = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const sockaddr_in address = loopback(port);
    const bool ok = ::connect(s, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0;
    ::close(s);
    return ok;
}

}  // namespace

bool waitFor(const std::function<bool()>& done, std::chrono::milliseconds guard) {
    const auto deadline = std::chrono::steady_clock::now() + guard;
    while (!done()) {
        if (std::chrono::steady_clock::now() > deadline) return false;
        std::this_thread::sleep_for(20ms);
    }
    return true;
}

int freeLoopbackPort() {
    const int s = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address = loopback(0);
    socklen_t length = sizeof address;
    if (::bind(s, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
        ::getsockname(s, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
        ::close(s);
        throw std::runtime_error("no free loopback port");
    }
    ::close(s);
    return ntohs(address.sin_port);
}

std::string readText(const std::filesystem::path& path) {
    std::stringstream text;
    text << std::ifstream(path).rdbuf();
    return text.str();
}

std::size_t occurrences(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

ChildProcess::ChildProcess(const std::vector<std::string>& argv, const std::filesystem::path& log) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    // The test runner may block signals; the child must see SIGTERM and SIGUSR1.
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    sigset_t none;
    sigemptyset(&none);
    posix_spawnattr_setsigmask(&attributes, &none);
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK);
    const int rc = posix_spawn(&pid_, args[0], &actions, &attributes, args.data(), environ);
    posix_spawnattr_destroy(&attributes);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) throw std::runtime_error("cannot start " + argv[0]);
}

ChildProcess::~ChildProcess() {
    if (pid_ > 0) {
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, nullptr, 0);
    }
}

void ChildProcess::signal(int s) const {
    if (pid_ > 0) ::kill(pid_, s);
}

int ChildProcess::awaitExit() {
    int status = 0;
    if (pid_ <= 0 || !waitFor([&] { return ::waitpid(pid_, &status, WNOHANG) == pid_; })) return -1;
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

bool ChildProcess::running() {
    return pid_ > 0 && ::waitpid(pid_, nullptr, WNOHANG) == 0;
}

Broker::Broker(const std::filesystem::path& dir, const std::string& extraConfig) : dir_(dir), port_(freeLoopbackPort()) {
    std::ofstream(dir_ / "mosquitto.conf") << "listener " << port_ << " 127.0.0.1\n"
                                           << "allow_anonymous true\npersistence false\n"
                                           << extraConfig;
}

void Broker::start() {
    process_.emplace(std::vector<std::string>{"/usr/sbin/mosquitto", "-c", (dir_ / "mosquitto.conf").string()},
                     dir_ / "mosquitto.log");
    if (!waitFor([&] { return accepting(port_); })) {
        throw std::runtime_error("mosquitto did not come up on port " + std::to_string(port_) + " (see " +
                                 (dir_ / "mosquitto.log").string() + ")");
    }
}

void Broker::stop() {
    if (!process_) return;
    process_->signal(SIGTERM);
    process_->awaitExit();
    process_.reset();
}

Subscriber::Subscriber(int port, const std::string& filter) {
    mosquitto_lib_init();
    client_ = mosquitto_new(nullptr, true, this);
    mosquitto_message_callback_set(client_, &Subscriber::onMessage);
    if (!waitFor([&] { return mosquitto_connect(client_, "127.0.0.1", port, 30) == MOSQ_ERR_SUCCESS; }) ||
        mosquitto_subscribe(client_, nullptr, filter.c_str(), 1) != MOSQ_ERR_SUCCESS ||
        mosquitto_loop_start(client_) != MOSQ_ERR_SUCCESS) {
        throw std::runtime_error("cannot subscribe to " + filter + " on port " + std::to_string(port));
    }
}

Subscriber::~Subscriber() {
    mosquitto_disconnect(client_);
    mosquitto_loop_stop(client_, false);
    mosquitto_destroy(client_);
}

void Subscriber::onMessage(mosquitto*, void* self, const mosquitto_message* message) {
    auto* s = static_cast<Subscriber*>(self);
    std::lock_guard lock(s->mutex_);
    s->received_[message->topic].emplace_back(static_cast<const char*>(message->payload),
                                              static_cast<std::size_t>(message->payloadlen));
}

std::vector<std::string> Subscriber::payloads(const std::string& topic) {
    std::lock_guard lock(mutex_);
    return received_[topic];
}

std::optional<std::string> Subscriber::await(const std::string& topic,
                                             const std::function<bool(const std::string&)>& accept, std::size_t skip) {
    std::optional<std::string> found;
    waitFor([&] {
        const auto all = payloads(topic);
        for (std::size_t i = skip; i < all.size(); ++i) {
            if (!accept || accept(all[i])) {
                found = all[i];
                return true;
            }
        }
        return false;
    });
    return found;
}

ModbusClient::ModbusClient(int port, int unit) : ctx_(modbus_new_tcp("127.0.0.1", port)) {
    if (ctx_ == nullptr || modbus_set_slave(ctx_, unit) != 0 || modbus_connect(ctx_) != 0) {
        const std::string why = modbus_strerror(errno);
        if (ctx_ != nullptr) modbus_free(ctx_);
        throw std::runtime_error("cannot connect a Modbus client to port " + std::to_string(port) + ": " + why);
    }
    modbus_set_response_timeout(ctx_, 5, 0);
}

ModbusClient::~ModbusClient() {
    modbus_close(ctx_);
    modbus_free(ctx_);
}

std::vector<std::uint16_t> ModbusClient::inputRegisters(int address, int count, int* error) {
    std::vector<std::uint16_t> values(static_cast<std::size_t>(count));
    const int n = modbus_read_input_registers(ctx_, address, count, values.data());
    if (error) *error = n < 0 ? errno : 0;
    values.resize(n < 0 ? 0 : static_cast<std::size_t>(n));
    return values;
}

std::vector<std::uint8_t> ModbusClient::discreteInputs(int address, int count, int* error) {
    std::vector<std::uint8_t> values(static_cast<std::size_t>(count));
    const int n = modbus_read_input_bits(ctx_, address, count, values.data());
    if (error) *error = n < 0 ? errno : 0;
    values.resize(n < 0 ? 0 : static_cast<std::size_t>(n));
    return values;
}

int ModbusClient::writeCoil(int address, bool on) {
    return modbus_write_bit(ctx_, address, on ? 1 : 0) == 1 ? 0 : errno;
}

int ModbusClient::readHoldingRegisters(int address, int count) {
    std::vector<std::uint16_t> values(static_cast<std::size_t>(count));
    return modbus_read_registers(ctx_, address, count, values.data()) == count ? 0 : errno;
}

std::uint32_t uint32At(const std::vector<std::uint16_t>& registers, int address) {
    const auto i = static_cast<std::size_t>(address);
    return (static_cast<std::uint32_t>(registers.at(i)) << 16) | registers.at(i + 1);
}

float floatAt(const std::vector<std::uint16_t>& registers, int address) {
    return std::bit_cast<float>(uint32At(registers, address));
}

}  // namespace icewatch::daemon::scada::test
