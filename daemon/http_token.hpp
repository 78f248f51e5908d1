#pragma once

#include <string>
#include <string_view>

#include "core/config/config.hpp"

namespace icewatch::daemon {

struct HttpToken {
    std::string value;    // empty: no token could be had, and every POST is refused
    std::string problem;  // why value is empty
};

// The bearer token the HTTP API demands for every POST: http.token when set, else the first line
// of http.token_file. With create, a missing file is made with 32 random bytes in hex, mode 0640,
// group icewatch when that group exists (the unit runs this as root before the service starts).
HttpToken resolveHttpToken(const config::HttpConfig& config, bool create);

// Compares a presented token with the expected one in time independent of where they differ.
bool sameToken(std::string_view presented, std::string_view expected);

}  // namespace icewatch::daemon
