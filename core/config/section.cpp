// Typed, range-checked reading of one JSON object of a configuration file. Every error names the
// file and the dotted key, because the person reading it is on a tower with a laptop.
#include "core/config/section.hpp"

#include <cmath>
#include <limits>

namespace icewatch::config {

namespace {
const nlohmann::json& emptyObject() {
    static const nlohmann::json kEmpty = nlohmann::json::object();
    return kEmpty;
}

std::string typeName(const nlohmann::json& value) {
    return value.type_name();
}

// An unsigned value above INT64_MAX would wrap to a negative number in get<std::int64_t>().
bool fitsInt64(const nlohmann::json& value) {
    return !value.is_number_unsigned() ||
           value.get<std::uint64_t>() <= static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
}
}  // namespace

Section::Section(const nlohmann::json& object, std::string file, std::string path)
    : object_(object.is_object() ? object : emptyObject()), file_(std::move(file)), path_(std::move(path)) {
    if (!object.is_object() && !object.is_null()) {
        throw ConfigError(file_ + ": " + (path_.empty() ? std::string("top level") : path_) +
                          ": must be an object, got " + typeName(object));
    }
}

std::string Section::keyPath(const std::string& key) const {
    return path_.empty() ? key : path_ + "." + key;
}

void Section::fail(const std::string& key, const std::string& what) const {
    throw ConfigError(file_ + ": " + keyPath(key) + ": " + what);
}

void Section::reject(const std::string& key, const std::string& what) const {
    if (problems_ == nullptr) fail(key, what);
    problems_->push_back(file_ + ": " + keyPath(key) + ": " + what);
}

template <class Body>
void Section::guarded(Body&& body) {
    if (problems_ == nullptr) {
        body();
        return;
    }
    try {
        body();
    } catch (const ConfigError& e) {
        problems_->push_back(e.what());
    }
}

const nlohmann::json* Section::find(const std::string& key) {
    consumed_.insert(key);
    auto it = object_.find(key);
    if (it == object_.end()) {
        return nullptr;
    }
    return &*it;
}

bool Section::has(const std::string& key) const {
    return object_.contains(key);
}

void Section::read(const std::string& key, bool& out) {
    guarded([&] {
        const nlohmann::json* value = find(key);
        if (value == nullptr) {
            return;
        }
        if (!value->is_boolean()) {
            fail(key, "must be true or false, got " + typeName(*value));
        }
        out = value->get<bool>();
    });
}

void Section::read(const std::string& key, int& out, int min, int max) {
    guarded([&] {
        const nlohmann::json* value = find(key);
        if (value == nullptr) {
            return;
        }
        if (!value->is_number_integer()) {
            fail(key, "must be an integer, got " + (value->is_number() ? value->dump() : typeName(*value)));
        }
        if (!fitsInt64(*value)) {
            fail(key, "must be between " + std::to_string(min) + " and " + std::to_string(max) + ", got " + value->dump());
        }
        const auto v = value->get<std::int64_t>();
        if (v < min || v > max) {
            fail(key, "must be between " + std::to_string(min) + " and " + std::to_string(max) + ", got " +
                          std::to_string(v));
        }
        out = static_cast<int>(v);
    });
}

void Section::read(const std::string& key, double& out, double min, double max) {
    guarded([&] {
        const nlohmann::json* value = find(key);
        if (value == nullptr) {
            return;
        }
        if (!value->is_number()) {
            fail(key, "must be a number, got " + typeName(*value));
        }
        const double v = value->get<double>();
        if (!std::isfinite(v) || v < min || v > max) {
            fail(key, "must be between " + nlohmann::json(min).dump() + " and " + nlohmann::json(max).dump() +
                          ", got " + value->dump());
        }
        out = v;
    });
}

void Section::read(const std::string& key, std::string& out) {
    guarded([&] {
        const nlohmann::json* value = find(key);
        if (value == nullptr) {
            return;
        }
        if (!value->is_string()) {
            fail(key, "must be a string, got " + typeName(*value));
        }
        out = value->get<std::string>();
    });
}

void Section::readChoice(const std::string& key, std::string& out, const std::set<std::string>& allowed) {
    guarded([&] {
        std::string value = out;
        read(key, value);
        if (allowed.count(value) == 0) {
            std::string list;
            for (const auto& a : allowed) {
                list += (list.empty() ? "" : ", ") + a;
            }
            fail(key, "must be one of " + list + ", got \"" + value + "\"");
        }
        out = value;
    });
}

void Section::read(const std::string& key, std::vector<double>& out) {
    guarded([&] {
        const nlohmann::json* value = find(key);
        if (value == nullptr) {
            return;
        }
        if (!value->is_array()) {
            fail(key, "must be an array of numbers, got " + typeName(*value));
        }
        std::vector<double> result;
        for (std::size_t i = 0; i < value->size(); ++i) {
            const auto& element = (*value)[i];
            if (!element.is_number() || !std::isfinite(element.get<double>())) {
                fail(key + "[" + std::to_string(i) + "]", "must be a finite number, got " + element.dump());
            }
            result.push_back(element.get<double>());
        }
        out = std::move(result);
    });
}

void Section::read(const std::string& key, std::map<std::string, std::int64_t>& out) {
    guarded([&] {
        const nlohmann::json* value = find(key);
        if (value == nullptr) {
            return;
        }
        if (!value->is_object()) {
            fail(key, "must be an object of name: integer, got " + typeName(*value));
        }
        std::map<std::string, std::int64_t> result;
        for (auto it = value->begin(); it != value->end(); ++it) {
            if (!it.value().is_number_integer() || !fitsInt64(it.value())) {
                fail(key + "." + it.key(), "must be an integer, got " + it.value().dump());
            }
            result[it.key()] = it.value().get<std::int64_t>();
        }
        out = std::move(result);
    });
}

Section Section::child(const std::string& key) {
    const nlohmann::json* value = find(key);
    const bool usable = value != nullptr && (value->is_object() || problems_ == nullptr);
    if (value != nullptr && !usable && !value->is_null()) {
        problems_->push_back(file_ + ": " + keyPath(key) + ": must be an object, got " + typeName(*value));
    }
    Section section(usable ? *value : emptyObject(), file_, keyPath(key));
    section.problems_ = problems_;
    return section;
}

void Section::finish() const {
    for (auto it = object_.begin(); it != object_.end(); ++it) {
        if (consumed_.count(it.key()) == 0) {
            reject(it.key(), "unknown key");
        }
    }
}

}  // namespace icewatch::config
