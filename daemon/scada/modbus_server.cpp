// Modbus TCP through libmodbus: libmodbus parses every request and builds every answer; this file
// only decides which requests reach it (the unit, the functions the map has) and what the coils
// do. The single server thread polls the listening socket and every connection, reads one request
// from a connection that has data, and answers it from the current register image before reading
// the next; the image is copied in under the lock, never held while talking to a client.
#include "daemon/scada/modbus_server.hpp"

#include <modbus.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <vector>

#include "core/common/error.hpp"
#include "drivers/log/log.hpp"

namespace icewatch::daemon::scada {

namespace {

using Steady = std::chrono::steady_clock;

std::shared_ptr<spdlog::logger> logger() {
    return log::get("modbus");
}

// The Modbus/TCP spec lets a client address a direct server as 0 or 255 as well as by its unit.
bool addressedToUs(int unit, int unitId) {
    return unit == unitId || unit == 0 || unit == MODBUS_TCP_SLAVE;
}

bool isCoilFunction(int function) {
    return function == MODBUS_FC_READ_COILS || function == MODBUS_FC_WRITE_SINGLE_COIL ||
           function == MODBUS_FC_WRITE_MULTIPLE_COILS;
}

// The functions the map has: inputs and input registers always, coils when writes are allowed.
// Everything else (holding registers included: there are none) is an illegal function.
bool supported(int function, bool allowWrites) {
    if (function == MODBUS_FC_READ_DISCRETE_INPUTS || function == MODBUS_FC_READ_INPUT_REGISTERS) return true;
    return allowWrites && isCoilFunction(function);
}

int portOf(int socket) {
    sockaddr_storage address{};
    socklen_t length = sizeof address;
    if (::getsockname(socket, reinterpret_cast<sockaddr*>(&address), &length) != 0) return -1;
    if (address.ss_family == AF_INET6) return ntohs(reinterpret_cast<sockaddr_in6*>(&address)->sin6_port);
    return ntohs(reinterpret_cast<sockaddr_in*>(&address)->sin_port);
}

}  // namespace

struct ModbusServer::Context {
    struct Client {
        int fd;
        Steady::time_point lastHeard;
    };

    ~Context() {
        for (const Client& c : clients) ::close(c.fd);
        if (listenFd >= 0) ::close(listenFd);
        if (mapping) modbus_mapping_free(mapping);
        if (ctx) modbus_free(ctx);
    }

    modbus_t* ctx = nullptr;
    modbus_mapping_t* mapping = nullptr;
    int listenFd = -1;
    std::vector<Client> clients;
    std::uint16_t heartbeat = 0;
    bool stale = true;
    std::uint64_t shownVersion = 0;  // the image version the stale bit was judged for
    bool fullLogged = false;
};

ModbusServer::ModbusServer(const config::ModbusConfig& config, ModbusHooks hooks, ModbusLimits limits)
    : config_(config), hooks_(std::move(hooks)), limits_(limits), context_(std::make_unique<Context>()) {
    const auto address = config::parseListenAddress(config.listen);
    if (!address) {
        throw Error(kExitConfig, "scada.modbus.listen: not host:port: \"" + config.listen + "\"");
    }
    const std::string where = config.listen;
    Context& c = *context_;
    c.ctx = modbus_new_tcp_pi(address->host.c_str(), std::to_string(address->port).c_str());
    if (c.ctx == nullptr) {
        throw Error(kExitUnavailable, "modbus: cannot set up " + where + ": " + modbus_strerror(errno));
    }
    // Pause before libmodbus flushes a malformed request, and the longest wait between the bytes
    // of one request: a request arrives in one TCP segment, so both can be short.
    modbus_set_response_timeout(c.ctx, 0, 100000);
    modbus_set_byte_timeout(c.ctx, 0, 200000);
    c.listenFd = modbus_tcp_pi_listen(c.ctx, limits_.maxClients);
    if (c.listenFd < 0) {
        throw Error(kExitUnavailable, "modbus: cannot listen on " + where + ": " + std::strerror(errno) +
                                          " (address in use, or not an address of this machine)");
    }
    port_ = portOf(c.listenFd);
    c.mapping = modbus_mapping_new_start_address(0, config_.allowWrites ? kCoilCount : 0, 0, kDiscreteInputCount, 0,
                                                 0, 0, kInputRegisterCount);
    if (c.mapping == nullptr) {
        throw Error(kExitSoftware, std::string("modbus: cannot allocate the register map: ") + std::strerror(errno));
    }
    wakeFd_ = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    if (wakeFd_ < 0) {
        throw Error(kExitSoftware, std::string("modbus: cannot create an eventfd: ") + std::strerror(errno));
    }
    image_ = emptyImage();
    thread_ = std::thread([this] { serve(); });
    logger()->info("Modbus TCP on {} port {} (unit {}, writes {})", address->host, port_, config_.unitId,
                   config_.allowWrites ? "allowed" : "refused");
}

ModbusServer::~ModbusServer() {
    const std::uint64_t one = 1;
    if (::write(wakeFd_, &one, sizeof one) != sizeof one) {
        logger()->error("cannot wake the server thread: {}", std::strerror(errno));
    }
    if (thread_.joinable()) thread_.join();
    ::close(wakeFd_);
}

void ModbusServer::show(const RegisterImage& image) {
    std::lock_guard lock(mutex_);
    image_ = image;
    ++imageVersion_;
}

void ModbusServer::serve() {
    Context& c = *context_;
    auto nextTick = Steady::now() + std::chrono::seconds(1);

    // Called outside every lock of ours: the hooks take the daemon's.
    auto judgeStale = [&] { c.stale = hooks_.resultStale ? hooks_.resultStale() : false; };
    judgeStale();

    auto closeClient = [&](std::size_t i) {
        ::close(c.clients[i].fd);
        c.clients.erase(c.clients.begin() + static_cast<std::ptrdiff_t>(i));
        c.fullLogged = false;
    };

    // The current image into libmodbus's map, in one piece, with the server's own live values.
    auto loadImage = [&] {
        std::uint64_t version;
        {
            std::lock_guard lock(mutex_);
            version = imageVersion_;
        }
        if (version != c.shownVersion) {
            judgeStale();  // a new result: its staleness, not the previous one's
            c.shownVersion = version;
        }
        std::lock_guard lock(mutex_);
        RegisterImage image = image_;
        image.inputs[kStale] = c.stale;
        image.registers[kHeartbeatRegister] = c.heartbeat;
        std::copy(image.inputs.begin(), image.inputs.end(), c.mapping->tab_input_bits);
        std::copy(image.registers.begin(), image.registers.end(), c.mapping->tab_input_registers);
    };

    // One request from client i; false when the connection is done.
    auto answer = [&](std::size_t i) {
        std::array<std::uint8_t, MODBUS_TCP_MAX_ADU_LENGTH> query{};
        modbus_set_socket(c.ctx, c.clients[i].fd);
        const int length = modbus_receive(c.ctx, query.data());
        if (length < 0) return false;  // closed, or not a Modbus frame libmodbus can follow
        if (length == 0) return true;
        c.clients[i].lastHeard = Steady::now();
        const int header = modbus_get_header_length(c.ctx);
        const int unit = query[static_cast<std::size_t>(header - 1)];
        const int function = query[static_cast<std::size_t>(header)];
        if (!addressedToUs(unit, config_.unitId)) {
            return modbus_reply_exception(c.ctx, query.data(), MODBUS_EXCEPTION_GATEWAY_PATH) >= 0;
        }
        if (!supported(function, config_.allowWrites)) {
            return modbus_reply_exception(c.ctx, query.data(), MODBUS_EXCEPTION_ILLEGAL_FUNCTION) >= 0;
        }
        loadImage();
        if (modbus_reply(c.ctx, query.data(), length, c.mapping) < 0) return false;
        // Coils are requests, not state: act on a 1 and read 0 again.
        for (int coil = 0; coil < c.mapping->nb_bits; ++coil) {
            if (c.mapping->tab_bits[coil] == 0) continue;
            c.mapping->tab_bits[coil] = 0;
            const auto& action = coil == kMeasureNowCoil ? hooks_.measureNow : hooks_.resetAlarm;
            logger()->info("coil {} written by a client: {}", coil, coil == kMeasureNowCoil ? "measure now" : "reset the alarm");
            if (action) action();
        }
        return true;
    };

    auto accept = [&] {
        int listenFd = c.listenFd;
        const int fd = modbus_tcp_pi_accept(c.ctx, &listenFd);
        if (fd < 0) return;
        if (static_cast<int>(c.clients.size()) >= limits_.maxClients) {
            if (!c.fullLogged) logger()->warn("{} clients already connected: refusing more", c.clients.size());
            c.fullLogged = true;
            ::close(fd);
            return;
        }
        // A client that stops reading must not hold the server in send().
        const timeval sendTimeout{1, 0};
        ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &sendTimeout, sizeof sendTimeout);
        const int one = 1;
        ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
        c.clients.push_back({fd, Steady::now()});
        logger()->debug("client connected ({} now)", c.clients.size());
    };

    std::vector<pollfd> fds;
    while (true) {
        fds.assign({{wakeFd_, POLLIN, 0}, {c.listenFd, POLLIN, 0}});
        for (const auto& client : c.clients) fds.push_back({client.fd, POLLIN, 0});
        const auto untilTick = std::chrono::duration_cast<std::chrono::milliseconds>(nextTick - Steady::now());
        const int timeoutMs = static_cast<int>(std::clamp<std::int64_t>(untilTick.count(), 0, 1000));
        if (::poll(fds.data(), fds.size(), timeoutMs) < 0 && errno != EINTR) {
            logger()->error("poll failed: {}; the Modbus server stops", std::strerror(errno));
            return;
        }
        if (fds[0].revents != 0) return;
        const auto now = Steady::now();
        if (now >= nextTick) {
            if (!hooks_.loopAlive || hooks_.loopAlive()) ++c.heartbeat;  // wraps at 65535
            judgeStale();
            nextTick = std::max(nextTick + std::chrono::seconds(1), now);
        }
        // Connections first, newest last: indices of fds[2 + i] match clients[i] until one closes.
        for (std::size_t i = c.clients.size(); i-- > 0;) {
            const short events = fds[2 + i].revents;
            if (events == 0) continue;
            if ((events & (POLLERR | POLLNVAL)) != 0 || !answer(i)) closeClient(i);
        }
        for (std::size_t i = c.clients.size(); i-- > 0;) {
            if (now - c.clients[i].lastHeard > limits_.idleTimeout) {
                logger()->debug("closing a connection silent for {} ms", limits_.idleTimeout.count());
                closeClient(i);
            }
        }
        if (fds[1].revents != 0) accept();
    }
}

}  // namespace icewatch::daemon::scada
