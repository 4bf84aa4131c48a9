#pragma once
/// INI helpers on top of MRPT's config classes: load a file with a clear error, and report
/// keys that no loader knows (a typo in an INI must not be silently ignored).
///
/// Usage:
///   auto cfg = devslam::core::loadIni("config_ini/tum_fr1.ini");
///   opts.loadFromConfigFile(*cfg, "tracking");
///   devslam::core::requireKnownKeys(*cfg, "tracking", {"n_features", "scale_factor"}, path);
///   n_features = devslam::core::readInt(*cfg, "orb", "n_features", n_features);

#include <mrpt/config/CConfigFileMemory.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace devslam::core {

/// Reads an INI file into memory (never written back). Throws std::runtime_error naming
/// the path when it is missing or unreadable.
[[nodiscard]] std::unique_ptr<mrpt::config::CConfigFileMemory> loadIni(const std::string& path);

/// Keys of `section` that are not in `known` (case-sensitive, MRPT keys are).
[[nodiscard]] std::vector<std::string> unknownKeys(const mrpt::config::CConfigFileBase& cfg,
                                                   const std::string& section,
                                                   const std::vector<std::string>& known);

/// Throws std::invalid_argument "<source> [section]: unknown key 'x' (known: a, b, c)"
/// when the section holds a key that is not in `known`; without a source the message names
/// only the field ("[section]: ..."), as the strict reads below, so that namingSource names
/// the file.
void requireKnownKeys(const mrpt::config::CConfigFileBase& cfg, const std::string& section,
                      const std::vector<std::string>& known, const std::string& source = "");

/// Throws std::invalid_argument "<source>: unknown section [x] (known: a, b, box_*)" when the
/// INI holds a section that is not in `known`, where an entry ending in '*' admits every
/// section that starts with what precedes it; and "<source>: key 'k' before the first
/// section" for a key no section holds (without a source, the message alone). A mistyped
/// section name would otherwise be ignored without a word, with every key in it.
void requireKnownSections(const mrpt::config::CConfigFileBase& cfg,
                          const std::vector<std::string>& known, const std::string& source = "");

/// Applies "section.key=value" items to an INI held in memory, blanks around the names and
/// the value dropped as in an INI line. Throws std::invalid_argument naming `what` and the
/// item when one is malformed.
void applyOverrides(mrpt::config::CConfigFileMemory& cfg, const std::vector<std::string>& items,
                    const std::string& what = "override");

/// The items of a whitespace-separated override list as INIs write them ("a.b=1 c.d=2":
/// [run] filter_overrides, a bench sequence's `set`, a scenario's `room_set`). A value in
/// brackets may hold blanks, as MRPT writes vectors: "p.path=[3.5 2.1] p.speed=1" is two
/// items. Throws std::invalid_argument naming `what` when a '[' is not closed.
[[nodiscard]] std::vector<std::string> overrideItems(const std::string& text,
                                                     const std::string& what = "override list");

/// The section names of the INI file `path` in the order the file gives them. MRPT's
/// getAllSections() sorts them; a list the user wrote (the bench's sequences) keeps
/// the user's order this way. Sections of `cfg` (the same file, loaded) that the scan
/// does not find come last, in MRPT's order, so none is ever lost.
[[nodiscard]] std::vector<std::string> sectionsInFileOrder(
    const mrpt::config::CConfigFileBase& cfg, const std::string& path);

/// The keys of `section`, in the order the file `path` gives them (MRPT's getAllKeys() sorts
/// them); keys the scan does not find come last, in MRPT's order.
[[nodiscard]] std::vector<std::string> keysInFileOrder(const mrpt::config::CConfigFileBase& cfg,
                                                       const std::string& path,
                                                       const std::string& section);

/// The INI holding [detector] and [dynamic_filter] for the config `cfg` read from `path`:
/// the file its [run] `filter_config` names (relative to `path`), or `path` itself when
/// there is none, with the [run] `filter_overrides` ("section.key=value ..." items)
/// applied. Throws naming the file when it cannot be read or an override is malformed.
[[nodiscard]] std::unique_ptr<mrpt::config::CConfigFileMemory> loadFilterIni(
    const mrpt::config::CConfigFileBase& cfg, const std::string& path);
/// The sections a filter INI holds: [detector] and [dynamic_filter].
[[nodiscard]] const std::vector<std::string>& filterSections();
/// The filter's INI named on a command line (`--config` of devslam-overlay and
/// devslam-filter-bench): a filter INI, which may hold only [detector] and [dynamic_filter],
/// or a SLAM INI (one with [run]), read through loadFilterIni. Throws naming the file when a
/// section is unknown or neither filter section is there. `source`, when given, receives
/// filterSource's name for what was read, for messages about its values (namingSource).
[[nodiscard]] std::unique_ptr<mrpt::config::CConfigFileMemory> loadFilterConfig(
    const std::string& path, std::string* source = nullptr);
/// The file loadFilterIni reads for the config `cfg` read from `path`.
[[nodiscard]] std::string filterIniPath(const mrpt::config::CConfigFileBase& cfg,
                                        const std::string& path);
/// What a bad filter value came from, for messages: filterIniPath, and "with <path> [run]
/// filter_overrides" when the config overrides some of its keys.
[[nodiscard]] std::string filterSource(const mrpt::config::CConfigFileBase& cfg,
                                       const std::string& path);

/// Strict typed reads of one key (core/Parse.h rules; MRPT strips a trailing `//` comment
/// first). A missing key gives `def`, or throws when `required`; a value that does not
/// parse in full throws std::invalid_argument "[section] key: expected an integer, got
/// '12x'". Use these instead of MRPT's read_int/read_double/read_bool, which take "12x"
/// as 12, "1e3" as 1 and "ture" as false without a word.
[[nodiscard]] int readInt(const mrpt::config::CConfigFileBase& cfg, const std::string& section,
                          const std::string& key, int def, bool required = false);
[[nodiscard]] std::uint64_t readUint64(const mrpt::config::CConfigFileBase& cfg,
                                       const std::string& section, const std::string& key,
                                       std::uint64_t def, bool required = false);
/// The text of `key`, or std::nullopt when the key is absent. A key given with no value
/// ("look_at =") is its empty text, for the caller's parser to refuse: not the default.
[[nodiscard]] std::optional<std::string> readTextIfPresent(const mrpt::config::CConfigFileBase& cfg,
                                                           const std::string& section,
                                                           const std::string& key);
[[nodiscard]] double readDouble(const mrpt::config::CConfigFileBase& cfg,
                                const std::string& section, const std::string& key, double def,
                                bool required = false);
[[nodiscard]] bool readBool(const mrpt::config::CConfigFileBase& cfg, const std::string& section,
                            const std::string& key, bool def, bool required = false);

/// Writes [section] key so that the reads above give `value` back exactly. MRPT's write prints
/// a real number with six decimals ("%f", "%e" outside [1e-4, 1e4]), so a saved 0.000123456
/// came back as 0.000123 and 123456.789 as 123456.8: a real number here gets the fewest digits
/// that read back to the same double (std::to_chars), a list of them "[a b c]". Anything else
/// is written as MRPT writes it (an int as digits, a bool as true/false). The saveToConfig of
/// every options class writes through this.
void writeKey(mrpt::config::CConfigFileBase& cfg, const std::string& section,
              const std::string& key, double value);
void writeKey(mrpt::config::CConfigFileBase& cfg, const std::string& section,
              const std::string& key, const std::vector<double>& values);
template <class T, class = std::enable_if_t<!std::is_floating_point_v<T>>>
void writeKey(mrpt::config::CConfigFileBase& cfg, const std::string& section,
              const std::string& key, const T& value) {
    cfg.write(section, key, value);
}

/// Runs `load()` and returns what it returns. A std::invalid_argument whose message names
/// only the field ("[section] key: ...", as the reads above and requireValue throw) comes
/// back as "<source> [section] key: ...", so a loader that reads one file can name it; so
/// does a std::runtime_error that starts with a section (a file a key names: "[detector]
/// yolo weights: file not found").
template <class Load>
decltype(auto) namingSource(const std::string& source, Load&& load) {
    try {
        return load();
    } catch (const std::invalid_argument& e) {
        const std::string msg = e.what();
        if (msg.empty() || msg.front() != '[') throw;
        throw std::invalid_argument(source + " " + msg);
    } catch (const std::runtime_error& e) {
        const std::string msg = e.what();
        if (msg.empty() || msg.front() != '[') throw;
        throw std::runtime_error(source + " " + msg);
    }
}

/// Throws std::invalid_argument naming section and key when `ok` is false.
void requireValue(bool ok, const std::string& section, const std::string& key,
                  const std::string& what);

}  // namespace devslam::core
