#include <devslam/core/Config.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace devslam::core {

std::unique_ptr<mrpt::config::CConfigFileMemory> loadIni(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open INI file '" + path + "'");
    std::stringstream ss;
    ss << in.rdbuf();
    if (in.bad()) throw std::runtime_error("cannot read INI file '" + path + "'");
    return std::make_unique<mrpt::config::CConfigFileMemory>(ss.str());
}

std::vector<std::string> unknownKeys(const mrpt::config::CConfigFileBase& cfg,
                                     const std::string& section,
                                     const std::vector<std::string>& known) {
    std::vector<std::string> keys, unknown;
    cfg.getAllKeys(section, keys);
    for (const auto& k : keys)
        if (std::find(known.begin(), known.end(), k) == known.end()) unknown.push_back(k);
    return unknown;
}

void requireKnownKeys(const mrpt::config::CConfigFileBase& cfg, const std::string& section,
                      const std::vector<std::string>& known, const std::string& source) {
    const auto unknown = unknownKeys(cfg, section, known);
    if (unknown.empty()) return;
    std::string list;
    for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
    throw std::invalid_argument(source + " [" + section + "]: unknown key '" + unknown.front() +
                                "' (known: " + list + ")");
}

void requireValue(bool ok, const std::string& section, const std::string& key,
                  const std::string& what) {
    if (!ok) throw std::invalid_argument("[" + section + "] " + key + ": " + what);
}

}  // namespace devslam::core
