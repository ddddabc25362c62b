#include "neepp/base/options.h"

#include <cmath>
#include <stdexcept>

namespace neepp {
namespace {

[[noreturn]] void bad_value(const std::string &key, const std::string &value, const char *type) {
    throw std::invalid_argument("option '" + key + "': '" + value + "' is not a valid " + type);
}

}  // namespace

int Options::get_int(const std::string &key, int def) const {
    asked_.insert(key);
    auto it = values_.find(key);
    if (it == values_.end()) return def;
    used_.insert(key);
    size_t pos = 0;
    int v = 0;
    try { v = std::stoi(it->second, &pos); } catch (...) { bad_value(key, it->second, "integer"); }
    if (pos != it->second.size()) bad_value(key, it->second, "integer");
    return v;
}

float Options::get_float(const std::string &key, float def) const {
    asked_.insert(key);
    auto it = values_.find(key);
    if (it == values_.end()) return def;
    used_.insert(key);
    size_t pos = 0;
    float v = 0;
    try { v = std::stof(it->second, &pos); } catch (...) { bad_value(key, it->second, "number"); }
    // nan and inf parse, but no option means anything by them.
    if (pos != it->second.size() || !std::isfinite(v)) bad_value(key, it->second, "finite number");
    return v;
}

bool Options::get_bool(const std::string &key, bool def) const {
    asked_.insert(key);
    auto it = values_.find(key);
    if (it == values_.end()) return def;
    used_.insert(key);
    const std::string &s = it->second;
    if (s == "true" || s == "1" || s == "yes" || s == "on") return true;
    if (s == "false" || s == "0" || s == "no" || s == "off") return false;
    bad_value(key, s, "boolean");
}

std::string Options::get_string(const std::string &key, const std::string &def) const {
    asked_.insert(key);
    auto it = values_.find(key);
    if (it == values_.end()) return def;
    used_.insert(key);
    return it->second;
}

std::vector<std::string> Options::unused() const {
    std::vector<std::string> r;
    for (const auto &[k, v] : values_)
        if (!used_.count(k)) r.push_back(k);
    return r;
}

}  // namespace neepp
