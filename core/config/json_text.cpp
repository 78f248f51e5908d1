// JSON parsing for every document a person or another program writes (the configuration,
// recording.json, the state files). nlohmann's DOM parser throws several exception types and does
// not say where a number overflowed; a SAX handler that keeps the key path answers both.
#include "core/config/json_text.hpp"

#include <vector>

namespace icewatch::config {

namespace {

using Json = nlohmann::json;
using DomParser = nlohmann::detail::json_sax_dom_parser<Json>;

// Builds the DOM like the stock parser and remembers where in the tree it is.
class PathTrackingParser : public DomParser {
public:
    explicit PathTrackingParser(Json& document) : DomParser(document, /*allow_exceptions=*/false) {}

    bool null() { return scalar(DomParser::null()); }
    bool boolean(bool v) { return scalar(DomParser::boolean(v)); }
    bool number_integer(Json::number_integer_t v) { return scalar(DomParser::number_integer(v)); }
    bool number_unsigned(Json::number_unsigned_t v) { return scalar(DomParser::number_unsigned(v)); }
    bool number_float(Json::number_float_t v, const Json::string_t& s) { return scalar(DomParser::number_float(v, s)); }
    bool string(Json::string_t& v) { return scalar(DomParser::string(v)); }
    bool binary(Json::binary_t& v) { return scalar(DomParser::binary(v)); }
    bool start_object(std::size_t n) {
        frames_.push_back({false, {}, 0});
        return DomParser::start_object(n);
    }
    bool key(Json::string_t& k) {
        frames_.back().key = k;
        return DomParser::key(k);
    }
    bool end_object() {
        frames_.pop_back();
        return scalar(DomParser::end_object());
    }
    bool start_array(std::size_t n) {
        frames_.push_back({true, {}, 0});
        return DomParser::start_array(n);
    }
    bool end_array() {
        frames_.pop_back();
        return scalar(DomParser::end_array());
    }
    bool parse_error(std::size_t position, const std::string& token, const nlohmann::detail::exception& e) {
        if (e.id == 406) {  // out_of_range: number overflow
            error_ = (path().empty() ? std::string("top level") : path()) + ": the number " + token +
                     " does not fit a double (must be finite)";
        } else {
            error_ = "not valid JSON at byte " + std::to_string(position) +
                     (path().empty() ? std::string() : " (in " + path() + ")") + ": " + e.what();
        }
        return false;
    }

    const std::string& error() const { return error_; }

private:
    struct Frame {
        bool array;
        std::string key;
        std::size_t index;
    };

    // A value ended: the enclosing array moves on to its next element.
    bool scalar(bool ok) {
        if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
        return ok;
    }

    std::string path() const {
        std::string p;
        for (const Frame& f : frames_) {
            if (f.array) {
                p += "[" + std::to_string(f.index) + "]";
            } else if (!f.key.empty()) {
                p += (p.empty() ? "" : ".") + f.key;
            }
        }
        return p;
    }

    std::vector<Frame> frames_;
    std::string error_;
};

}  // namespace

JsonText parseJsonText(std::string_view text) {
    JsonText result;
    PathTrackingParser parser(result.value);
    bool ok = false;
    try {
        ok = Json::sax_parse(text.begin(), text.end(), &parser, nlohmann::detail::input_format_t::json,
                             /*strict=*/true, /*ignore_comments=*/true);
    } catch (const Json::exception& e) {
        // Not expected with allow_exceptions off; kept so that no parser path can escape.
        result.error = std::string("not valid JSON: ") + e.what();
    }
    if (!ok) {
        if (result.error.empty()) result.error = parser.error().empty() ? "not valid JSON" : parser.error();
        result.value = nullptr;
    }
    return result;
}

}  // namespace icewatch::config
