// Integrator options as key=value strings (from the scene file and -I on the command line), with typed
// getters that reject malformed values and report keys nobody asked for.
#pragma once
#include <map>
#include <set>
#include <string>
#include <vector>

namespace neepp {

class Options {
public:
    Options() = default;
    explicit Options(std::map<std::string, std::string> values) : values_(std::move(values)) {}
    void set(const std::string &key, const std::string &value) { values_[key] = value; }
    bool has(const std::string &key) const { return values_.count(key) != 0; }
    int get_int(const std::string &key, int def) const;
    float get_float(const std::string &key, float def) const;
    bool get_bool(const std::string &key, bool def) const;
    std::string get_string(const std::string &key, const std::string &def) const;
    // Keys that were set but never read: a typo in -I should be an error, not silently ignored.
    std::vector<std::string> unused() const;
    // Every key a getter was asked for, set or not (tests check the option table against it).
    const std::set<std::string> &asked() const { return asked_; }
    const std::map<std::string, std::string> &values() const { return values_; }

private:
    std::map<std::string, std::string> values_;
    mutable std::set<std::string> used_, asked_;
};

}  // namespace neepp
