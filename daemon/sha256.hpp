#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace icewatch::daemon {

// Lower-case hex SHA-256 (OpenSSL libcrypto).
std::string sha256Hex(std::string_view bytes);
// Of a file's bytes; nullopt when it cannot be read.
std::optional<std::string> sha256OfFile(const std::filesystem::path& path);

}  // namespace icewatch::daemon
