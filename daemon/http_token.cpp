// The credentials of the HTTP API. A token is always needed for a POST: the baseline decides what
// the daemon calls "no ice", and a web page in any browser on the box can reach 127.0.0.1.
#include "daemon/http_token.hpp"

#include <fcntl.h>
#include <grp.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>

#include <openssl/crypto.h>

#include "drivers/log/log.hpp"

namespace icewatch::daemon {

namespace {

constexpr std::size_t kTokenBytes = 32;

std::string randomHex(std::string& problem) {
    std::array<unsigned char, kTokenBytes> bytes{};
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::getrandom(bytes.data() + done, bytes.size() - done, 0);
        if (n < 0) {
            if (errno == EINTR) continue;
            problem = std::string("getrandom: ") + std::strerror(errno);
            return {};
        }
        done += static_cast<std::size_t>(n);
    }
    static constexpr char kHex[] = "0123456789abcdef";
    std::string hex;
    for (unsigned char b : bytes) {
        hex += kHex[b >> 4];
        hex += kHex[b & 15];
    }
    return hex;
}

// Creates the file exclusively (a concurrent start cannot make two tokens) with the token in it.
bool createTokenFile(const std::string& path, std::string& problem) {
    const std::string token = randomHex(problem);
    if (token.empty()) return false;
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0640);
    if (fd < 0) {
        problem = "cannot create " + path + ": " + std::strerror(errno);
        return errno == EEXIST;  // someone else made it: read theirs
    }
    // open() applies the umask; the mode must be exactly 0640 whatever the caller's umask.
    bool ok = ::fchmod(fd, 0640) == 0;
    if (const group* g = ::getgrnam("icewatch"); g != nullptr && ::geteuid() == 0) {
        ok = ::fchown(fd, 0, g->gr_gid) == 0 && ok;
    }
    const std::string line = token + "\n";
    ok = ::write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size()) && ::fsync(fd) == 0 && ok;
    ::close(fd);
    if (!ok) {
        problem = "cannot write " + path + ": " + std::strerror(errno);
        ::unlink(path.c_str());
        return false;
    }
    log::get("http")->info("created the HTTP token file {} (mode 0640)", path);
    return true;
}

}  // namespace

HttpToken resolveHttpToken(const config::HttpConfig& config, bool create) {
    if (!config.token.empty()) {
        return {config.token, {}};
    }
    const std::string& path = config.tokenFile;
    if (create && ::access(path.c_str(), F_OK) != 0) {
        std::string problem;
        if (!createTokenFile(path, problem)) {
            return {{}, problem};
        }
    }
    std::ifstream in(path);
    if (!in) {
        return {{}, "cannot read the token file " + path + ": " + std::strerror(errno)};
    }
    std::string token;
    std::getline(in, token);
    while (!token.empty() && (token.back() == '\r' || token.back() == ' ' || token.back() == '\t')) token.pop_back();
    if (token.size() < 16) {
        return {{}, path + ": the token must be at least 16 characters on the first line"};
    }
    return {token, {}};
}

bool sameToken(std::string_view presented, std::string_view expected) {
    // The length is not secret (the generated one is always 64); the bytes are.
    return presented.size() == expected.size() && !expected.empty() &&
           CRYPTO_memcmp(presented.data(), expected.data(), expected.size()) == 0;
}

}  // namespace icewatch::daemon
