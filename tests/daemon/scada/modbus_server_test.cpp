// The Modbus TCP server against libmodbus's client and raw sockets: the values it was shown, the
// exceptions for what the map does not have, writes only when allowed, garbage and silence, more
// than one client, and registers that change together.
#include "daemon/scada/modbus_server.hpp"

#include <arpa/inet.h>
#include <modbus.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <thread>

#include <gtest/gtest.h>

#include "core/common/error.hpp"
#include "tests/daemon/scada/scada_rig.hpp"

namespace icewatch::daemon::scada::test {
namespace {

struct Calls {
    std::atomic<int> measure{0}, reset{0};
    std::atomic<bool> alive{true}, stale{false};
};

ModbusHooks hooksFor(Calls& calls) {
    return {[&calls] { ++calls.measure; }, [&calls] { ++calls.reset; }, [&calls] { return calls.alive.load(); },
            [&calls] { return calls.stale.load(); }};
}

config::ModbusConfig loopback(bool allowWrites = false) {
    return {"127.0.0.1:0", 1, allowWrites};
}

nlohmann::json resultDocument() {
    return {{"time", "2026-01-01T00:10:00Z"}, {"status", "ok"},         {"volume_mm3", 427174.25},
            {"uncertainty_mm3", 21000.5},     {"mean_thickness_mm", 3.75}, {"max_thickness_mm", nullptr},
            {"mean_thickness_uncertainty_mm", 0.1875}, {"alarm", "alarm"}};
}

// A plain TCP connection, for what no Modbus client would send.
class RawConnection {
public:
    explicit RawConnection(int port) : fd_(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0)) {
        sockaddr_in address{};
        address.sin_family = AF_INET;
        address.sin_port = htons(static_cast<std::uint16_t>(port));
        address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        if (::connect(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
            throw std::runtime_error("cannot connect");
        }
    }
    ~RawConnection() { ::close(fd_); }
    void send(const std::vector<std::uint8_t>& bytes) const {
        ASSERT_EQ(::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL), static_cast<ssize_t>(bytes.size()));
    }
    // What arrives within the guard, up to `want` bytes; stops early at the end of the stream.
    std::vector<std::uint8_t> receive(std::size_t want, bool* closed = nullptr) const {
        std::vector<std::uint8_t> bytes;
        const auto deadline = std::chrono::steady_clock::now() + kGuard;
        while (bytes.size() < want && std::chrono::steady_clock::now() < deadline) {
            pollfd p{fd_, POLLIN, 0};
            if (::poll(&p, 1, 50) != 1) continue;
            std::uint8_t buffer[512];
            const ssize_t n = ::recv(fd_, buffer, std::min(sizeof buffer, want - bytes.size()), 0);
            if (n <= 0) {
                if (closed) *closed = true;
                break;
            }
            bytes.insert(bytes.end(), buffer, buffer + n);
        }
        return bytes;
    }
    bool closedByPeer() const {
        bool closed = false;
        receive(1 << 20, &closed);
        return closed;
    }

private:
    int fd_;
};

TEST(ModbusServer, ServesTheRegistersOfTheResultItWasShown) {
    Calls calls;
    ModbusServer server(loopback(), hooksFor(calls));
    server.show(imageOf(resultDocument(), true, 7));
    ModbusClient client(server.port());
    int error = 0;
    const auto registers = client.inputRegisters(0, kInputRegisterCount, &error);
    ASSERT_EQ(registers.size(), 18u) << modbus_strerror(error);
    EXPECT_EQ(registers[0], 2) << "map version";
    EXPECT_EQ(registers[1], 0) << "status ok";
    EXPECT_EQ(registers[2], 2) << "alarm level alarm";
    EXPECT_FLOAT_EQ(floatAt(registers, 4), 427174.25f);
    EXPECT_FLOAT_EQ(floatAt(registers, 6), 21000.5f);
    EXPECT_FLOAT_EQ(floatAt(registers, 8), 3.75f);
    EXPECT_TRUE(std::isnan(floatAt(registers, 10))) << "max thickness is null";
    EXPECT_EQ(uint32At(registers, 12), 1767226200u);
    EXPECT_EQ(uint32At(registers, 14), 7u);
    EXPECT_FLOAT_EQ(floatAt(registers, 16), 0.1875f) << "mean thickness uncertainty";
    const auto inputs = client.discreteInputs(0, kDiscreteInputCount, &error);
    EXPECT_EQ(inputs, (std::vector<std::uint8_t>{1, 1, 0, 0, 1})) << modbus_strerror(error);
}

TEST(ModbusServer, ReadsPastTheMapGetIllegalDataAddressAndTheConnectionStaysUsable) {
    Calls calls;
    ModbusServer server(loopback(), hooksFor(calls));
    ModbusClient client(server.port());
    int error = 0;
    EXPECT_TRUE(client.inputRegisters(16, 4, &error).empty());
    EXPECT_EQ(error, EMBXILADD);
    client.inputRegisters(18, 1, &error);
    EXPECT_EQ(error, EMBXILADD);
    client.discreteInputs(0, 6, &error);
    EXPECT_EQ(error, EMBXILADD);
    client.discreteInputs(5, 1, &error);
    EXPECT_EQ(error, EMBXILADD);
    EXPECT_EQ(client.readHoldingRegisters(0, 1), EMBXILFUN) << "there are no holding registers";
    EXPECT_EQ(client.inputRegisters(0, 16, &error).size(), 16u) << modbus_strerror(error);
}

TEST(ModbusServer, WritesAreRefusedUnlessAllowed) {
    Calls calls;
    ModbusServer server(loopback(false), hooksFor(calls));
    ModbusClient client(server.port());
    EXPECT_EQ(client.writeCoil(kMeasureNowCoil, true), EMBXILFUN);
    EXPECT_EQ(client.writeCoil(kResetAlarmCoil, true), EMBXILFUN);
    std::uint8_t coils[2];
    EXPECT_EQ(modbus_read_bits(client.context(), 0, 2, coils), -1);
    EXPECT_EQ(errno, EMBXILFUN);
    EXPECT_EQ(modbus_write_register(client.context(), 0, 1), -1);
    EXPECT_EQ(errno, EMBXILFUN);
    EXPECT_EQ(calls.measure, 0);
    EXPECT_EQ(calls.reset, 0);
}

TEST(ModbusServer, CoilsAskForAMeasurementAndAnAlarmResetWhenAllowed) {
    Calls calls;
    ModbusServer server(loopback(true), hooksFor(calls));
    ModbusClient client(server.port());
    // The server acts once its answer is out: wait for the request to arrive.
    EXPECT_EQ(client.writeCoil(kMeasureNowCoil, true), 0);
    EXPECT_TRUE(waitFor([&] { return calls.measure == 1; }));
    EXPECT_EQ(client.writeCoil(kResetAlarmCoil, true), 0);
    EXPECT_TRUE(waitFor([&] { return calls.reset == 1; }));
    EXPECT_EQ(client.writeCoil(kMeasureNowCoil, false), 0) << "writing 0 is accepted and asks nothing";
    const std::uint8_t both[2] = {1, 1};
    EXPECT_EQ(modbus_write_bits(client.context(), 0, 2, both), 2);
    EXPECT_TRUE(waitFor([&] { return calls.measure == 2 && calls.reset == 2; }));
    std::uint8_t coils[2] = {9, 9};
    ASSERT_EQ(modbus_read_bits(client.context(), 0, 2, coils), 2);
    EXPECT_EQ(coils[0], 0) << "a coil is a request, not a state";
    EXPECT_EQ(coils[1], 0);
    EXPECT_EQ(client.writeCoil(kCoilCount, true), EMBXILADD);
}

TEST(ModbusServer, AnswersItsUnitAndTheDirectAddressesOnly) {
    Calls calls;
    ModbusServer server({"127.0.0.1:0", 7, false}, hooksFor(calls));
    int error = 0;
    ModbusClient own(server.port(), 7);
    EXPECT_EQ(own.inputRegisters(0, 1, &error).size(), 1u) << modbus_strerror(error);
    ModbusClient direct(server.port(), MODBUS_TCP_SLAVE);
    EXPECT_EQ(direct.inputRegisters(0, 1, &error).size(), 1u) << modbus_strerror(error);
    ModbusClient other(server.port(), 8);
    other.inputRegisters(0, 1, &error);
    EXPECT_EQ(error, EMBXGPATH);
}

TEST(ModbusServer, GarbageGetsExceptionsOrAClosedConnectionAndServingGoesOn) {
    Calls calls;
    ModbusServer server(loopback(), hooksFor(calls));
    {
        // An HTTP request: libmodbus reads it as frames for unit 'H' of function 'T'.
        RawConnection http(server.port());
        const std::string request = "GET / HTTP/1.1\r\nHost: x\r\n\r\n";
        http.send(std::vector<std::uint8_t>(request.begin(), request.end()));
        const auto answer = http.receive(9);
        ASSERT_EQ(answer.size(), 9u) << "an exception response: MBAP header, function | 0x80, code";
        EXPECT_EQ(answer[6], 'H') << "the 7th byte of the request was taken as the unit";
        EXPECT_EQ(answer[7], 'T' | 0x80) << "the 8th byte of the request was taken as the function";
        EXPECT_EQ(answer[8], MODBUS_EXCEPTION_GATEWAY_PATH);
    }
    {
        // A well-formed frame of a function nobody defined.
        RawConnection unknown(server.port());
        unknown.send({0x12, 0x34, 0x00, 0x00, 0x00, 0x02, 0xFF, 0x41});
        const auto answer = unknown.receive(9);
        EXPECT_EQ(answer, (std::vector<std::uint8_t>{0x12, 0x34, 0x00, 0x00, 0x00, 0x03, 0xFF, 0xC1,
                                                     MODBUS_EXCEPTION_ILLEGAL_FUNCTION}));
    }
    {
        // A write of 255 bytes cannot fit in an ADU: libmodbus gives up on the stream.
        RawConnection oversized(server.port());
        oversized.send({0x00, 0x01, 0x00, 0x00, 0x01, 0x06, 0xFF, 0x10, 0x00, 0x00, 0x00, 0x7F, 0xFF});
        EXPECT_TRUE(oversized.closedByPeer());
    }
    {
        // Half a request and then nothing: closed after the byte timeout.
        RawConnection half(server.port());
        half.send({0x00, 0x01, 0x00, 0x00, 0x00, 0x06, 0xFF, 0x04, 0x00});
        EXPECT_TRUE(half.closedByPeer());
    }
    ModbusClient client(server.port());
    int error = 0;
    EXPECT_EQ(client.inputRegisters(0, 16, &error).size(), 16u) << modbus_strerror(error);
}

TEST(ModbusServer, ASilentClientHoldsNothingUpAndIsClosedWhenIdle) {
    Calls calls;
    ModbusServer server(loopback(), hooksFor(calls), {16, std::chrono::milliseconds(300)});
    RawConnection silent(server.port());
    ModbusClient client(server.port());
    int error = 0;
    EXPECT_EQ(client.inputRegisters(0, 16, &error).size(), 16u) << modbus_strerror(error);
    EXPECT_TRUE(silent.closedByPeer());
}

TEST(ModbusServer, ServesSeveralClientsAtOnceAndRefusesBeyondTheLimit) {
    Calls calls;
    ModbusServer server(loopback(), hooksFor(calls), {2, std::chrono::milliseconds(60000)});
    ModbusClient a(server.port());
    ModbusClient b(server.port());
    std::atomic<int> answered{0};
    auto poll = [&answered](ModbusClient& client) {
        for (int i = 0; i < 50; ++i) {
            const auto registers = client.inputRegisters(0, 16);
            if (registers.size() == 16 && registers[0] == kMapVersion) ++answered;
        }
    };
    std::thread ta(poll, std::ref(a));
    std::thread tb(poll, std::ref(b));
    ta.join();
    tb.join();
    EXPECT_EQ(answered, 100);
    RawConnection third(server.port());
    EXPECT_TRUE(third.closedByPeer()) << "a third connection is over the limit of 2";
    EXPECT_EQ(a.inputRegisters(0, 1).size(), 1u) << "the first two are still served";
}

TEST(ModbusServer, RegistersOfOneResultChangeTogether) {
    Calls calls;
    ModbusServer server(loopback(), hooksFor(calls));
    // Every image carries k in the volume, the time and the count; a read that mixed two images
    // would show two different values.
    std::atomic<bool> done{false};
    std::thread writer([&] {
        for (std::uint32_t k = 1; !done; ++k) {
            nlohmann::json document = resultDocument();
            document["volume_mm3"] = static_cast<double>(k % 1000000);
            document["time"] = nullptr;
            RegisterImage image = imageOf(document, false, k % 1000000);
            image.registers[kResultTimeRegister] = static_cast<std::uint16_t>((k % 1000000) >> 16);
            image.registers[kResultTimeRegister + 1] = static_cast<std::uint16_t>(k % 1000000);
            server.show(image);
        }
    });
    ModbusClient client(server.port());
    int torn = 0, read = 0, failed = 0;
    std::uint32_t lastCount = 0;
    int changes = 0;
    while (changes < 50 && read + failed < 20000) {
        const auto r = client.inputRegisters(0, 16);
        if (r.size() != 16) {
            ++failed;
            continue;
        }
        ++read;
        const std::uint32_t count = uint32At(r, 14);
        if (static_cast<std::uint32_t>(floatAt(r, 4)) != count || uint32At(r, 12) != count) ++torn;
        if (count != lastCount) ++changes;
        lastCount = count;
    }
    done = true;
    writer.join();
    EXPECT_EQ(failed, 0);
    EXPECT_EQ(torn, 0) << "of " << read << " reads";
    EXPECT_EQ(changes, 50) << "the images did change under the reads";
}

TEST(ModbusServer, HeartbeatCountsWhileTheLoopIsAliveAndStaleFollowsTheDaemon) {
    Calls calls;
    ModbusServer server(loopback(), hooksFor(calls));
    ModbusClient client(server.port());
    auto heartbeat = [&] { return client.inputRegisters(kHeartbeatRegister, 1).at(0); };
    const auto first = heartbeat();
    EXPECT_TRUE(waitFor([&] { return heartbeat() != first; })) << "no beat within the guard";
    EXPECT_EQ(client.discreteInputs(kStale, 1).at(0), 0);

    calls.alive = false;
    calls.stale = true;
    ASSERT_TRUE(waitFor([&] { return client.discreteInputs(kStale, 1).at(0) == 1; }));
    // The stale bit is judged on the same tick as the beat: from here no beat may come.
    const auto stopped = heartbeat();
    std::this_thread::sleep_for(std::chrono::milliseconds(2200));
    EXPECT_EQ(heartbeat(), stopped) << "two ticks passed without the loop alive";

    calls.stale = false;
    server.show(imageOf(resultDocument(), false, 1));
    EXPECT_EQ(client.discreteInputs(kStale, 1).at(0), 0) << "a new result is judged at once";
}

TEST(ModbusServer, AnAddressInUseIsUnavailable) {
    Calls calls;
    ModbusServer first(loopback(), hooksFor(calls));
    const std::string taken = "127.0.0.1:" + std::to_string(first.port());
    try {
        ModbusServer second({taken, 1, false}, hooksFor(calls));
        FAIL() << "a second server listened on " << taken;
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), kExitUnavailable);
        EXPECT_NE(std::string(e.what()).find("cannot listen on " + taken), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace icewatch::daemon::scada::test
