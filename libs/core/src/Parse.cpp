#include <devslam/core/Parse.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>
#include <stdexcept>

namespace devslam::core {
std::string trimmed(const std::string& text) {
    const auto blank = [](unsigned char c) { return std::isspace(c) != 0; };
    const auto b = std::find_if_not(text.begin(), text.end(), blank);
    const auto e = std::find_if_not(text.rbegin(), text.rend(), blank).base();
    return b < e ? std::string(b, e) : std::string();
}

std::string clipped(const std::string& text, std::size_t max) {
    if (text.size() <= max) return text;
    std::size_t cut = max;
    while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;
    return text.substr(0, cut) + "... (" + std::to_string(text.size()) + " bytes)";
}

std::string shortestReal(double v) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}

std::string lowercase(std::string text) {
    for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return text;
}

namespace {

[[noreturn]] void fail(const std::string& what, const std::string& expected,
                       const std::string& text) {
    throw std::invalid_argument(what + ": expected " + expected + ", got '" + clipped(text) + "'");
}

/// strtod also reads C's hexadecimal numbers ("0x10" is 16, "0x1p-5"), which no reader of
/// an INI or a TUM file (Python's float()) takes for numbers: refused.
bool hexadecimal(const std::string& t) {
    return t.find_first_of("xX") != std::string::npos;
}

}  // namespace

bool readFinite(const std::string& t, double& v) {
    if (hexadecimal(t)) return false;
    char* end = nullptr;
    errno = 0;
    v = std::strtod(t.c_str(), &end);
    // strtod sets ERANGE on underflow too ("1e-320", "1e-400": a subnormal or 0), which
    // Python's float() reads without complaint; only overflow (+-HUGE_VAL) is refused.
    const bool overflow = errno == ERANGE && std::fabs(v) > 1.0;
    return !t.empty() && end == t.c_str() + t.size() && !overflow && std::isfinite(v);
}

double parseNumber(const std::string& text, const std::string& what) {
    double v = 0;
    if (!readFinite(trimmed(text), v)) fail(what, "a number", text);
    return v;
}

long long parseInteger(const std::string& text, const std::string& what, long long min,
                       long long max) {
    const std::string t = trimmed(text);
    if (t.empty()) fail(what, "an integer", text);
    // Plain digits go through strtoll, exact over the whole 64-bit range; other spellings
    // (exponents, $eval{} output) through strtod, which is exact up to 2^53.
    char* end = nullptr;
    errno = 0;
    long long v = std::strtoll(t.c_str(), &end, 10);
    if (end != t.c_str() + t.size() || errno == ERANGE) {
        double d = 0;  // (readFinite refuses hexadecimal)
        if (!readFinite(t, d) || d != std::floor(d) || std::fabs(d) > 9007199254740992.0)
            fail(what, "an integer", text);
        v = static_cast<long long>(d);
    }
    if (v < min || v > max) {
        const bool no_min = min == std::numeric_limits<long long>::min();
        const bool no_max = max == std::numeric_limits<long long>::max();
        fail(what,
             no_max   ? "an integer >= " + std::to_string(min)
             : no_min ? "an integer <= " + std::to_string(max)
                      : "an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]",
             text);
    }
    return v;
}

bool parseBool(const std::string& text, const std::string& what) {
    const std::string t = lowercase(trimmed(text));
    if (t == "true" || t == "yes" || t == "on" || t == "1") return true;
    if (t == "false" || t == "no" || t == "off" || t == "0") return false;
    fail(what, "true or false", text);
}

std::vector<double> parseNumberList(const std::string& text, const std::string& what,
                                    std::size_t expected) {
    // At most one pair of brackets around the whole list: "[2.4 1.6 2.4 4.4" (a ']' lost in an
    // edit) was read as if it were closed.
    const auto open = std::count(text.begin(), text.end(), '[');
    const auto close = std::count(text.begin(), text.end(), ']');
    if (open != close || open > 1 ||
        (open == 1 &&
         (text.find('[') > text.find(']') || text.find_first_not_of(" \t") != text.find('[') ||
          text.find_last_not_of(" \t") != text.find(']'))))
        throw std::invalid_argument(what + ": '" + clipped(text) +
                                    "' has unmatched brackets (write [a b c] or a b c)");
    std::string t = text;
    for (char& c : t)
        if (c == '[' || c == ']' || c == ',' || c == ';') c = ' ';
    std::istringstream ss(t);
    std::vector<double> out;
    std::string tok;
    while (ss >> tok) {
        double v = 0;
        if (!readFinite(tok, v)) {
            // "nan", "inf" and "1e400" read in full, but are no place, size or time.
            char* end = nullptr;
            std::strtod(tok.c_str(), &end);
            const bool whole = !hexadecimal(tok) && end == tok.c_str() + tok.size();
            throw std::invalid_argument(what + ": '" + clipped(tok) + "' is not a " +
                                        (whole ? "finite number" : "number"));
        }
        out.push_back(v);
    }
    if (expected > 0 && out.size() != expected)
        throw std::invalid_argument(what + ": expected " + std::to_string(expected) +
                                    " numbers, got " + std::to_string(out.size()));
    return out;
}

bool endsWithNoCase(const std::string& text, const std::string& suffix) {
    return text.size() >= suffix.size() &&
           lowercase(text.substr(text.size() - suffix.size())) == lowercase(suffix);
}

bool endsWith(const std::string& text, const std::string& suffix) {
    return text.size() >= suffix.size() &&
           text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

namespace {
bool anOption(const std::string& word) {
    return word.rfind("--", 0) == 0;
}
}  // namespace

std::string optionValue(const std::vector<std::string>& args, std::size_t& i) {
    if (i + 1 >= args.size() || anOption(args[i + 1]))
        throw std::invalid_argument(args[i] + " needs a value");
    return args[++i];
}

std::string optionValue(int argc, char** argv, int& i) {
    if (i + 1 >= argc || anOption(argv[i + 1]))
        throw std::invalid_argument(std::string(argv[i]) + " needs a value");
    return argv[++i];
}

void refuseRepeatedOptions(const std::vector<std::string>& args,
                           const std::vector<std::string>& repeatable,
                           const std::vector<std::pair<std::string, std::string>>& aliases) {
    std::set<std::string> seen;
    for (const auto& word : args) {
        std::string option = word;
        for (const auto& [alias, name] : aliases)
            if (word == alias) option = name;
        if (!anOption(option) || option == "--help" ||
            std::find(repeatable.begin(), repeatable.end(), option) != repeatable.end())
            continue;
        if (!seen.insert(option).second)
            throw std::invalid_argument(option +
                                        " is given twice (give it once: the last one would "
                                        "replace the first)");
    }
}

void refuseRepeatedOptions(int argc, char** argv, const std::vector<std::string>& repeatable,
                           const std::vector<std::pair<std::string, std::string>>& aliases) {
    refuseRepeatedOptions(std::vector<std::string>(argv + std::min(argc, 1), argv + argc),
                          repeatable, aliases);
}

}  // namespace devslam::core
