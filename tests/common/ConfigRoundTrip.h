#pragma once
// A round-trip test for every key of an options class, written once for all of them.
//
//   devslam::test::expectEveryKeyRoundTrips(
//       [](const Ini& in, Ini& out) { SlamOptions::fromConfig(in).saveToConfig(out); },
//       {{"loop_closure", "mode", {"off"}}});
//
// `loadSave` loads fresh options from `in` (throwing std::invalid_argument for a value it
// refuses) and saves them into `out`. Starting from what the defaults save, every saved key
// is set in turn to another value the loader accepts; the key must come back from save with
// exactly that value and every other key unchanged (a key saved but read into the wrong field,
// or not read at all, or saved with less precision than it was read, fails here). And every
// key the loader knows, as its "unknown key" message lists them, must be saved.
//
// Other values are made up by type: a bool is flipped; an integer moves by 1, -1, 2, then
// doubles or halves (then, as it may be a real number that prints as one, is tried as one); a
// real number is scaled or shifted by factors with nine significant digits (what a
// six-digit format would lose); a list of numbers shifts every item. A text value has no
// natural neighbour, so the caller names the alternatives of each text key (`texts`); a text
// key with none fails the test rather than pass untested (KeyNotes).
#include <mrpt/config/CConfigFileMemory.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace devslam::test {

using Ini = mrpt::config::CConfigFileMemory;
using LoadSave = std::function<void(const Ini& in, Ini& out)>;

/// Other values a text key may take: {section, key, {values...}}.
struct TextAlternatives {
    std::string section, key;
    std::vector<std::string> values;
};

/// What the test cannot tell from the values alone.
struct KeyNotes {
    std::vector<TextAlternatives> texts;  ///< other values of the text keys
    /// {section, key} saved but not an option: a detector's name, which selects the class
    /// (every other value belongs to another options class).
    std::vector<std::pair<std::string, std::string>> fixed;
    /// {section, key} read but saved as other keys: a camera preset, saved as its values.
    std::vector<std::pair<std::string, std::string>> unsaved;
};

namespace detail {

inline std::string exact(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

inline std::vector<double> numbersOf(const std::string& text, bool& ok) {
    std::string t = text;
    for (char& c : t)
        if (c == '[' || c == ']' || c == ',') c = ' ';
    std::istringstream in(t);
    std::vector<double> out;
    std::string item;
    ok = true;
    while (in >> item) {
        try {
            std::size_t used = 0;
            out.push_back(std::stod(item, &used));
            if (used != item.size()) ok = false;
        } catch (const std::exception&) {
            ok = false;
        }
    }
    if (out.empty()) ok = false;
    return out;
}

/// Candidate values for `text`, most natural first; empty for a text value.
inline std::vector<std::string> candidatesFor(const std::string& text) {
    if (text == "true") return {"false"};
    if (text == "false") return {"true"};
    std::vector<std::string> out;
    const auto b = text.find_first_not_of(" \t"), e = text.find_last_not_of(" \t");
    const std::string t = b == std::string::npos ? "" : text.substr(b, e - b + 1);
    const std::size_t digits = !t.empty() && t[0] == '-' ? 1 : 0;
    if (t.size() > digits && t.size() < 19 &&
        std::all_of(t.begin() + digits, t.end(), [](char c) { return c >= '0' && c <= '9'; })) {
        // an integer, or a real number that prints as one
        const long long v = std::stoll(text);
        out = {std::to_string(v + 1), std::to_string(v - 1), std::to_string(v + 2),
               std::to_string(v * 2), std::to_string(v / 2)};
    }
    bool ok = false;
    const auto nums = numbersOf(text, ok);
    if (!ok) return out;
    const bool list = nums.size() > 1 || text.find('[') != std::string::npos;
    for (const auto& change : std::vector<std::function<double(double)>>{
             [](double v) { return v * 1.23456789; }, [](double v) { return v * 0.876543219; },
             [](double v) { return v + 0.123456789; }, [](double v) { return v - 0.0123456789; },
             [](double v) { return v * 1.0123456789; }, [](double v) { return v + 1.23456789; },
             [](double) { return 0.000123456789; }}) {
        std::string s = list ? "[" : "";
        for (std::size_t i = 0; i < nums.size(); ++i)
            s += (i ? " " : "") + exact(change(nums[i]));
        out.push_back(list ? s + "]" : s);
    }
    return out;
}

/// The same value? Numbers by value (a list item by item), the rest as text.
inline bool sameValue(const std::string& a, const std::string& b) {
    if (a == b) return true;
    bool oka = false, okb = false;
    const auto na = numbersOf(a, oka), nb = numbersOf(b, okb);
    return oka && okb && na == nb;
}

inline std::map<std::pair<std::string, std::string>, std::string> entries(const Ini& ini) {
    std::map<std::pair<std::string, std::string>, std::string> out;
    std::vector<std::string> sections;
    ini.getAllSections(sections);
    for (const auto& s : sections) {
        std::vector<std::string> keys;
        ini.getAllKeys(s, keys);
        for (const auto& k : keys) out[{s, k}] = ini.read_string(s, k, "", false);
    }
    return out;
}

inline Ini copyOf(const Ini& ini) {
    Ini c;
    for (const auto& [sk, v] : entries(ini)) c.write(sk.first, sk.second, v);
    return c;
}

}  // namespace detail

/// The keys the loader knows in `section`, read from its unknown-key message ("[s]: unknown
/// key 'x' (known: a, b)"). Fails the test when it accepts an unknown key.
inline std::set<std::string> knownKeys(const LoadSave& loadSave, const Ini& valid,
                                       const std::string& section) {
    Ini probe = detail::copyOf(valid);
    probe.write(section, "zz_not_a_key", "1");
    try {
        Ini out;
        loadSave(probe, out);
    } catch (const std::invalid_argument& e) {
        const std::string msg = e.what();
        const auto open = msg.find("(known: ");
        const auto close = msg.rfind(')');
        if (msg.find("'zz_not_a_key'") == std::string::npos || open == std::string::npos ||
            close == std::string::npos || close < open) {
            ADD_FAILURE() << "[" << section << "] an unknown key gave: " << msg;
            return {};
        }
        std::set<std::string> keys;
        std::istringstream in(msg.substr(open + 8, close - open - 8));
        std::string k;
        while (std::getline(in, k, ',')) {
            k.erase(0, k.find_first_not_of(' '));
            keys.insert(k);
        }
        return keys;
    }
    ADD_FAILURE() << "[" << section << "] accepts an unknown key";
    return {};
}

/// Starts from what `start` (by default an empty INI: the defaults) loads and saves; prints
/// how many keys it changed, so that a run shows the test was not empty.
inline void expectEveryKeyRoundTrips(const LoadSave& loadSave, const KeyNotes& notes = {},
                                     const Ini& start = Ini{}) {
    const auto listed = [](const auto& list, const std::pair<std::string, std::string>& sk) {
        return std::find(list.begin(), list.end(), sk) != list.end();
    };
    Ini base;
    loadSave(start, base);
    const auto saved = detail::entries(base);
    ASSERT_FALSE(saved.empty()) << "the defaults save nothing";

    std::set<std::string> sections;
    for (const auto& [sk, v] : saved) sections.insert(sk.first);
    for (const auto& s : sections) {
        for (const auto& k : knownKeys(loadSave, base, s))
            EXPECT_TRUE(saved.count({s, k}) || listed(notes.unsaved, {s, k}))
                << "[" << s << "] " << k << " is read, not saved";
    }

    int changed = 0;
    for (const auto& [sk, value] : saved) {
        const auto& [section, key] = sk;
        if (listed(notes.fixed, sk)) continue;
        auto candidates = detail::candidatesFor(value);
        for (const auto& t : notes.texts)
            if (t.section == section && t.key == key) candidates = t.values;
        if (candidates.empty()) {
            ADD_FAILURE() << "[" << section << "] " << key << " = '" << value
                          << "': a text key, and the test names no other value for it";
            continue;
        }
        bool tried = false;
        for (const auto& other : candidates) {
            if (detail::sameValue(other, value)) continue;
            Ini in = detail::copyOf(base);
            in.write(section, key, other);
            Ini out;
            try {
                loadSave(in, out);
            } catch (const std::invalid_argument&) {
                continue;  // out of the key's range: try the next value
            }
            tried = true;
            ++changed;
            const auto back = detail::entries(out);
            const auto it = back.find(sk);
            if (it == back.end()) {
                ADD_FAILURE() << "[" << section << "] " << key << " = " << other
                              << ": not saved any more";
            } else {
                EXPECT_TRUE(detail::sameValue(it->second, other))
                    << "[" << section << "] " << key << ": loaded " << other << ", saved "
                    << it->second;
            }
            for (const auto& [sk2, v2] : saved) {
                if (sk2 == sk) continue;
                const auto it2 = back.find(sk2);
                EXPECT_TRUE(it2 != back.end() && it2->second == v2)
                    << "[" << section << "] " << key << " = " << other << " changed ["
                    << sk2.first << "] " << sk2.second << " from " << v2 << " to "
                    << (it2 == back.end() ? std::string("(gone)") : it2->second);
            }
            break;
        }
        EXPECT_TRUE(tried) << "[" << section << "] " << key << " = " << value
                           << ": the loader refused every other value tried";
    }
    std::printf("round trip: %d of %zu saved keys changed, each read back and saved again\n",
                changed, saved.size());
}

}  // namespace devslam::test
