#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace icewatch::config {

struct JsonText {
    nlohmann::json value;  // discarded when error is set
    std::string error;     // empty: parsed
};

// Parses JSON text (// and /* */ comments allowed) without throwing. A syntax error names the
// byte position; a number that does not fit a double (1e999) names the dotted key that holds it,
// because nlohmann::json would otherwise throw out_of_range past every caller's parse_error catch.
JsonText parseJsonText(std::string_view text);

}  // namespace icewatch::config
