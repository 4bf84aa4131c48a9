#include <devslam/core/Config.h>
#include <devslam/core/GzFile.h>
#include <devslam/core/Parse.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

namespace devslam::core {

namespace {
/// Lines MRPT reads otherwise than they look, without a word, refused naming the line:
/// - a repeated key (names in any letter case; MRPT keeps the last) or section (MRPT merges
///   it into the first): a pasted line or section would replace a value the reader of the
///   file sees first (a goal, an obstacle, a gain); both lines are named;
/// - a '[' without ']', text after a section's ']', and a line that is neither a section
///   nor `key = value` (ignored);
/// - a comment ending in '\' followed by a key or section (MRPT joins them: the key is lost).
/// Comments (#, ;, //), @ directives and continued values ('\' at the end) are skipped.
void refuseMisreadLines(const std::string& text, const std::string& path) {
    std::map<std::string, int> sections;
    std::map<std::pair<std::string, std::string>, int> keys;
    std::map<std::string, std::string> defines;  // MRPT's "@define NAME VALUE", used as ${NAME}
    const auto expand = [&](std::string s) {
        // Each use replaced once, the search going on after the value put in: a value that
        // holds its own name ("@define A ${A}") searched from the start again for ever.
        for (const auto& [name, value] : defines)
            for (auto p = s.find("${" + name + "}"); p != std::string::npos;
                 p = s.find("${" + name + "}", p + value.size()))
                s.replace(p, name.size() + 3, value);
        return s;
    };
    std::istringstream in(text);
    std::string section;
    int n = 0;
    bool continued = false;   // the line before ended in '\': this one is part of its value
    bool in_comment = false;  // ... and it was a comment: this line is read as comment too
    const auto isComment = [](const std::string& line) {
        const auto a = line.find_first_not_of(" \t");
        return a == std::string::npos || line[a] == '#' || line[a] == ';' ||
               line.compare(a, 2, "//") == 0;
    };
    for (std::string line; std::getline(in, line);) {
        ++n;
        // No INI holds a control byte, so one is refused where it is: a NUL hid a key from the
        // checks ("bogus_key\0 = 1" passed requireKnownKeys), and a binary file given for the
        // INI was refused for its first "key", the raw bytes in the message.
        for (const char ch : line) {
            const auto c = static_cast<unsigned char>(ch);
            if ((c >= 0x20 && c != 0x7f) || c == '\r' || c == '\t') continue;
            char code[24];
            std::snprintf(code, sizeof code, c == 0 ? "a NUL byte" : "control byte 0x%02x", c);
            throw std::invalid_argument(path + " line " + std::to_string(n) + ": " + code +
                                        " (a binary file, or a damaged INI)");
        }
        if (!line.empty() && line.back() == '\r') line.pop_back();
        const bool continuation = continued;
        continued = !line.empty() && line.back() == '\\';  // MRPT joins only there
        if (continuation) {
            // A key or section joined to a comment is lost without a word ("# see C:\docs\"
            // above a key); a comment joined to one (a shell command's '\') is harmless.
            if (in_comment && !isComment(line))
                throw std::invalid_argument(path + " line " + std::to_string(n - 1) +
                                            ": a comment ends in '\\', so MRPT reads line " +
                                            std::to_string(n) + " ('" + clipped(trimmed(line)) +
                                            "') as part of it");
            continue;
        }
        in_comment = false;
        const auto a = line.find_first_not_of(" \t");
        if (a == std::string::npos) continue;
        if (isComment(line)) {
            in_comment = continued;
            continue;
        }
        if (line[a] == '@') {  // a directive: MRPT 2.5 knows @define alone
            std::istringstream d(line.substr(a));
            std::string word, name, value;
            d >> word >> name;
            std::getline(d, value);
            // Any other it skips without a word: "@include other.ini" read nothing.
            if (word != "@define")
                throw std::invalid_argument(path + " line " + std::to_string(n) + ": '" +
                                            clipped(word) +
                                            "' is no directive MRPT knows (only @define): the "
                                            "line would be ignored");
            if (!name.empty()) defines[name] = trimmed(value);
            continue;
        }
        if (line[a] == '[') {
            const auto b = line.find(']', a);
            if (b == std::string::npos)  // MRPT would make a section of it and the next line
                throw std::invalid_argument(path + " line " + std::to_string(n) + ": '" +
                                            clipped(trimmed(line)) + "' has no ']'");
            // After ']' only a comment: MRPT ignores the rest ("[orb] junk" is [orb]).
            const auto rest = line.find_first_not_of(" \t", b + 1);
            if (rest != std::string::npos && line[rest] != '#' && line[rest] != ';' &&
                line.compare(rest, 2, "//") != 0)
                throw std::invalid_argument(path + " line " + std::to_string(n) + ": '" +
                                            clipped(trimmed(line)) +
                                            "': text after the section's ']'");
            section = trimmed(expand(line.substr(a + 1, b - a - 1)));  // MRPT trims the name
            // MRPT files the keys after "[]" with those before any section, and the checks
            // then named the key but not the line.
            if (section.empty())
                throw std::invalid_argument(path + " line " + std::to_string(n) + ": '" +
                                            clipped(trimmed(line)) + "' names no section");
            const auto [at, fresh] = sections.emplace(lowercase(section), n);
            if (!fresh)
                throw std::invalid_argument(
                    path + " line " + std::to_string(n) + ": section " + line.substr(a, b - a + 1) +
                    " repeated (first at line " + std::to_string(at->second) + ")");
            continue;
        }
        const auto eq = line.find('=', a);
        if (eq == std::string::npos || eq == a)  // MRPT ignores such a line without a word
            throw std::invalid_argument(path + " line " + std::to_string(n) + ": '" +
                                        clipped(trimmed(line)) +
                                        "' is neither a [section] nor a key = value");
        const std::string key = trimmed(expand(line.substr(a, eq - a)));
        if (key.empty() || key.find("${") != std::string::npos) continue;  // not resolvable here
        if (section.empty())  // (requireKnownSections would name the key, not the line)
            throw std::invalid_argument(path + " line " + std::to_string(n) + ": key '" + key +
                                        "' before the first [section]");
        const auto [at, fresh] = keys.emplace(std::pair{lowercase(section), lowercase(key)}, n);
        if (!fresh)
            throw std::invalid_argument(path + " line " + std::to_string(n) + ": [" + section +
                                        "] " + key + " repeated (first at line " +
                                        std::to_string(at->second) + ")");
    }
}
}  // namespace

std::unique_ptr<mrpt::config::CConfigFileMemory> loadIni(const std::string& path) {
    // An ifstream opens a folder and then reads nothing: an empty INI, all defaults.
    if (std::filesystem::is_directory(path))
        throw std::runtime_error("INI file '" + path + "' is a folder");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot open INI file '" + path + "'");
    // Read up to a bound: /dev/zero (or a rawlog given for the INI) was read until memory ran
    // out ("std::bad_alloc", naming nothing). The largest INI shipped is a few kB.
    constexpr std::size_t kMaxIniBytes = std::size_t(16) << 20;
    std::string text;
    char chunk[1 << 16];
    while (in.read(chunk, sizeof chunk), in.gcount() > 0) {
        text.append(chunk, static_cast<std::size_t>(in.gcount()));
        if (text.size() > kMaxIniBytes)
            throw std::runtime_error("INI file '" + path + "' is over 16 MiB: not an INI file");
    }
    if (in.bad()) throw std::runtime_error("cannot read INI file '" + path + "'");
    // A UTF-8 byte-order mark (Windows editors write one) made the first line "neither a
    // [section] nor a key = value", and MRPT lost the first section to it.
    if (text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);
    refuseMisreadLines(text, path);
    try {
        return std::make_unique<mrpt::config::CConfigFileMemory>(text);
    } catch (const std::exception& e) {
        // MRPT's parser says "Line 73: Unknown variable ${REF_DIST}" (an @define missing or
        // misspelt) and names no file.
        throw std::runtime_error(path + ": " + innermostMessage(e.what()));
    }
}

void applyOverrides(mrpt::config::CConfigFileMemory& cfg, const std::vector<std::string>& items,
                    const std::string& what) {
    // One key set twice keeps the last without a word, as a key repeated in a file would.
    std::map<std::pair<std::string, std::string>, std::string> given;
    for (const auto& s : items) {
        const auto dot = s.find('.'), eq = s.find('=');
        // Blanks around the names and the value go, as in an INI line ("orb.n_features = 300"
        // as the file's "n_features = 300"; the names were kept with their blanks and refused).
        const std::string section = dot == std::string::npos ? "" : trimmed(s.substr(0, dot));
        const std::string key =
            dot == std::string::npos || eq == std::string::npos || dot > eq
                ? ""
                : trimmed(s.substr(dot + 1, eq - dot - 1));
        if (section.empty() || key.empty())
            throw std::invalid_argument(what + " '" + s + "': expected SECTION.KEY=VALUE");
        const auto [at, fresh] = given.emplace(std::pair{lowercase(section), lowercase(key)}, s);
        if (!fresh)
            throw std::invalid_argument(what + " '" + s + "': [" + section + "] " + key +
                                        " is set twice (also '" + at->second + "')");
        cfg.write(section, key, trimmed(s.substr(eq + 1)));
    }
}

std::vector<std::string> overrideItems(const std::string& text, const std::string& what) {
    std::vector<std::string> items;
    std::string item;
    int depth = 0;  // inside brackets, blanks belong to the item
    for (char c : text) {
        if (c == '[') ++depth;
        if (c == ']' && depth > 0) --depth;
        if (depth == 0 && std::isspace(static_cast<unsigned char>(c))) {
            if (!item.empty()) items.push_back(std::move(item));
            item.clear();
        } else {
            item += c;
        }
    }
    if (depth > 0)
        throw std::invalid_argument(what + " '" + text + "': a '[' is not closed");
    if (!item.empty()) items.push_back(std::move(item));
    return items;
}

namespace {
/// `known` reordered as the names `scan` finds in the file's lines (each line with the
/// section it is in); names the scan misses come last, in their own order.
template <class Scan>
std::vector<std::string> inFileOrder(const std::string& path, const std::vector<std::string>& known,
                                     Scan&& scan) {
    std::vector<std::string> ordered;
    const auto has = [](const std::vector<std::string>& v, const std::string& x) {
        return std::find(v.begin(), v.end(), x) != v.end();
    };
    std::ifstream in(path);
    std::string section;
    for (std::string line; std::getline(in, line);) {
        const auto a = line.find_first_not_of(" \t");
        if (a == std::string::npos) continue;
        if (line[a] == '[') {
            const auto b = line.find(']', a);
            if (b == std::string::npos) continue;
            section = line.substr(a + 1, b - a - 1);
        }
        const std::string name = scan(section, line.substr(a));
        if (!name.empty() && has(known, name) && !has(ordered, name)) ordered.push_back(name);
    }
    for (const auto& s : known)
        if (!has(ordered, s)) ordered.push_back(s);
    return ordered;
}
}  // namespace

std::vector<std::string> sectionsInFileOrder(const mrpt::config::CConfigFileBase& cfg,
                                             const std::string& path) {
    std::vector<std::string> known;
    cfg.getAllSections(known);
    return inFileOrder(path, known, [](const std::string& section, const std::string& line) {
        return line[0] == '[' ? section : std::string();
    });
}

std::vector<std::string> keysInFileOrder(const mrpt::config::CConfigFileBase& cfg,
                                         const std::string& path, const std::string& section) {
    std::vector<std::string> known;
    cfg.getAllKeys(section, known);
    return inFileOrder(path, known, [&](const std::string& sec, const std::string& line) {
        const auto eq = line.find('=');
        if (sec != section || line[0] == '[' || eq == std::string::npos) return std::string();
        const auto end = line.find_last_not_of(" \t", eq - 1);
        return end == std::string::npos || eq == 0 ? std::string() : line.substr(0, end + 1);
    });
}

std::string filterIniPath(const mrpt::config::CConfigFileBase& cfg, const std::string& path) {
    namespace fs = std::filesystem;
    const std::string fc = cfg.read_string("run", "filter_config", "");
    return fc.empty()                   ? path
           : fs::path(fc).is_absolute() ? fc
                                        : (fs::path(path).parent_path() / fc).string();
}

std::string filterSource(const mrpt::config::CConfigFileBase& cfg, const std::string& path) {
    std::string s = filterIniPath(cfg, path);
    if (!cfg.read_string("run", "filter_overrides", "").empty())
        s += " with " + path + " [run] filter_overrides";
    return s;
}

const std::vector<std::string>& filterSections() {
    static const std::vector<std::string> sections{"detector", "dynamic_filter"};
    return sections;
}

std::unique_ptr<mrpt::config::CConfigFileMemory> loadFilterIni(
    const mrpt::config::CConfigFileBase& cfg, const std::string& path) {
    const std::string fc = cfg.read_string("run", "filter_config", "");
    const std::string file = filterIniPath(cfg, path);
    if (!fc.empty() && !std::filesystem::is_regular_file(file))
        throw std::runtime_error(path + " [run] filter_config: " +
                                 (std::filesystem::exists(file) ? "not a regular file '"
                                                                : "no such file '") +
                                 file + "'");
    auto out = loadIni(file);
    // A file of its own holds only the filter's sections (else the SLAM INI's check covers it),
    // and at least one of them: an empty file, or the wrong one, ran the filter on its
    // defaults without a word.
    if (!fc.empty()) {
        requireKnownSections(*out, filterSections(), file);
        if (!out->sectionExists("detector") && !out->sectionExists("dynamic_filter"))
            throw std::invalid_argument(path + " [run] filter_config: '" + file +
                                        "' has no [detector] or [dynamic_filter] section");
    }
    const auto items = overrideItems(cfg.read_string("run", "filter_overrides", ""),
                                     path + " [run] filter_overrides");
    // An item for another section would add that section and be read by nothing.
    for (const auto& item : items) {
        const std::string section = item.substr(0, std::min(item.find('.'), item.find('=')));
        const auto& known = filterSections();
        if (std::find(known.begin(), known.end(), lowercase(section)) == known.end() &&
            item.find('.') < item.find('='))
            throw std::invalid_argument(path + " [run] filter_overrides item '" + item +
                                        "': section '" + section +
                                        "' is not one of the filter's (detector, dynamic_filter)");
    }
    applyOverrides(*out, items, path + " [run] filter_overrides item");
    return out;
}

std::unique_ptr<mrpt::config::CConfigFileMemory> loadFilterConfig(const std::string& path,
                                                                  std::string* source) {
    const auto ini = loadIni(path);
    if (source) *source = filterSource(*ini, path);
    // A SLAM INI's own sections are devslam-run's to check; loadFilterIni checks the file
    // its [run] filter_config names.
    if (!ini->sectionExists("run")) requireKnownSections(*ini, filterSections(), path);
    // Asked of the file itself (loadFilterIni checks a filter_config's): after [run]
    // filter_overrides, which make the sections they set, a SLAM INI whose filter_config line
    // was lost passed, and the filter ran on the code's defaults with the overrides on top.
    if (ini->read_string("run", "filter_config", "").empty() && !ini->sectionExists("detector") &&
        !ini->sectionExists("dynamic_filter"))
        throw std::invalid_argument(path +
                                    ": no [detector] or [dynamic_filter] section, and no [run] "
                                    "filter_config naming an INI that has them" +
                                    (ini->read_string("run", "filter_overrides", "").empty()
                                         ? std::string()
                                         : " ([run] filter_overrides only changes keys of one)"));
    return loadFilterIni(*ini, path);
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

void writeKey(mrpt::config::CConfigFileBase& cfg, const std::string& section,
              const std::string& key, double value) {
    cfg.write(section, key, shortestReal(value));
}

void writeKey(mrpt::config::CConfigFileBase& cfg, const std::string& section,
              const std::string& key, const std::vector<double>& values) {
    std::string text = "[";
    for (std::size_t i = 0; i < values.size(); ++i)
        text += (i ? " " : "") + shortestReal(values[i]);
    cfg.write(section, key, text + "]");
}

void requireKnownKeys(const mrpt::config::CConfigFileBase& cfg, const std::string& section,
                      const std::vector<std::string>& known, const std::string& source) {
    const auto unknown = unknownKeys(cfg, section, known);
    if (unknown.empty()) return;
    std::string list;
    for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
    throw std::invalid_argument((source.empty() ? "" : source + " ") + "[" + section +
                                "]: unknown key '" + unknown.front() + "' (known: " + list + ")");
}

void requireKnownSections(const mrpt::config::CConfigFileBase& cfg,
                          const std::vector<std::string>& known, const std::string& source) {
    const auto admitted = [&](const std::string& section) {
        for (const auto& k : known) {
            if (!k.empty() && k.back() == '*' ? section.rfind(k.substr(0, k.size() - 1), 0) == 0
                                              : section == k)
                return true;
        }
        return false;
    };
    const std::string in = source.empty() ? "" : source + ": ";
    std::vector<std::string> all;
    cfg.getAllSections(all);
    for (const auto& section : all) {
        if (section.empty()) {  // MRPT files keys written before any [section] under ""
            std::vector<std::string> keys;
            cfg.getAllKeys(section, keys);
            if (!keys.empty())
                throw std::invalid_argument(in + "key '" + keys.front() +
                                            "' before the first section");
            continue;
        }
        if (admitted(section)) continue;
        std::string list;
        for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
        throw std::invalid_argument(in + "unknown section [" + section + "] (known: " + list + ")");
    }
}

namespace {

/// The key's text, or nothing when it is absent (and not required).
bool readText(const mrpt::config::CConfigFileBase& cfg, const std::string& section,
              const std::string& key, bool required, std::string& text) {
    if (!cfg.keyExists(section, key)) {
        if (required)
            throw std::invalid_argument("[" + section + "] " + key + ": required key is missing");
        return false;
    }
    text = cfg.read_string(section, key, "");
    return true;
}

std::string field(const std::string& section, const std::string& key) {
    return "[" + section + "] " + key;
}

}  // namespace

int readInt(const mrpt::config::CConfigFileBase& cfg, const std::string& section,
            const std::string& key, int def, bool required) {
    std::string t;
    if (!readText(cfg, section, key, required, t)) return def;
    return static_cast<int>(parseInteger(t, field(section, key), std::numeric_limits<int>::min(),
                                         std::numeric_limits<int>::max()));
}

std::uint64_t readUint64(const mrpt::config::CConfigFileBase& cfg, const std::string& section,
                         const std::string& key, std::uint64_t def, bool required) {
    std::string t;
    if (!readText(cfg, section, key, required, t)) return def;
    return static_cast<std::uint64_t>(parseInteger(t, field(section, key), 0));
}

std::optional<std::string> readTextIfPresent(const mrpt::config::CConfigFileBase& cfg,
                                             const std::string& section, const std::string& key) {
    std::string t;
    if (!readText(cfg, section, key, false, t)) return std::nullopt;
    return t;
}

double readDouble(const mrpt::config::CConfigFileBase& cfg, const std::string& section,
                  const std::string& key, double def, bool required) {
    std::string t;
    if (!readText(cfg, section, key, required, t)) return def;
    return parseNumber(t, field(section, key));
}

bool readBool(const mrpt::config::CConfigFileBase& cfg, const std::string& section,
              const std::string& key, bool def, bool required) {
    std::string t;
    if (!readText(cfg, section, key, required, t)) return def;
    return parseBool(t, field(section, key));
}

void requireValue(bool ok, const std::string& section, const std::string& key,
                  const std::string& what) {
    if (!ok) throw std::invalid_argument("[" + section + "] " + key + ": " + what);
}

}  // namespace devslam::core
