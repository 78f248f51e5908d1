#pragma once

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/common/error.hpp"

namespace icewatch::config {

// Raised for anything wrong in a configuration file. The message always names the file and the
// dotted key ("/etc/icewatch/icewatch.json: camera.fps: must be between 1 and 120, got 500").
class ConfigError : public Error {
public:
    explicit ConfigError(const std::string& message) : Error(kExitConfig, message) {}
};

// A read-only view on one JSON object of a configuration file that knows its file and dotted
// path. Readers leave the target untouched when the key is absent (the struct's default stands),
// check type and range when present, and finish() rejects every key nobody asked for, so a typo
// is an error instead of a silently ignored setting.
class Section {
public:
    Section(const nlohmann::json& object, std::string file, std::string path);

    void read(const std::string& key, bool& out);
    void read(const std::string& key, int& out, int min, int max);
    void read(const std::string& key, double& out, double min, double max);
    void read(const std::string& key, std::string& out);
    // A string restricted to a set of allowed values (an enum in the file).
    void readChoice(const std::string& key, std::string& out, const std::set<std::string>& allowed);
    void read(const std::string& key, std::vector<double>& out);
    // A flat object of name -> integer (camera controls by name, for example).
    void read(const std::string& key, std::map<std::string, std::int64_t>& out);

    bool has(const std::string& key) const;
    // The nested object under key; an absent key gives an empty section.
    Section child(const std::string& key);
    // Throws ConfigError naming the first key that no reader consumed (collecting: notes each).
    void finish() const;

    // From now on, this section and its children note each problem in `problems` and go on
    // (the key keeps its default) instead of throwing at the first: `config check` reports them all.
    void collectProblems(std::vector<std::string>& problems) { problems_ = &problems; }

    // An error about key in this section: thrown, or noted when collecting.
    void reject(const std::string& key, const std::string& what) const;
    // An error about key in this section, always thrown (within a reader, which notes it when collecting).
    [[noreturn]] void fail(const std::string& key, const std::string& what) const;
    std::string keyPath(const std::string& key) const;
    const std::string& file() const { return file_; }

private:
    const nlohmann::json* find(const std::string& key);
    // Runs one reader; when collecting, its ConfigError is noted and the key keeps its value.
    template <class Body>
    void guarded(Body&& body);

    const nlohmann::json& object_;
    std::string file_;
    std::string path_;
    std::set<std::string> consumed_;
    std::vector<std::string>* problems_ = nullptr;
};

}  // namespace icewatch::config
