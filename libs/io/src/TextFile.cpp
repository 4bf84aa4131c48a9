#include "TextFile.h"

#include <devslam/core/Parse.h>

#include <devslam/core/Picture.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace devslam::io::detail {

namespace {
/// std::getline with a bound on the line's length: /dev/zero, or a 100 MB file of one line,
/// was read whole into memory (4.6 GB in 10 s) before any check saw it.
bool readLineCapped(std::istream& in, std::string& line, const std::string& path, int n) {
    line.clear();
    for (std::streambuf* sb = in.rdbuf();;) {
        int c = 0;
        try {  // (libstdc++'s filebuf throws on a read error, which getline turned into badbit)
            c = sb->sbumpc();
        } catch (const std::exception& e) {
            throw std::runtime_error("error reading '" + path + "': " + e.what());
        }
        if (c == std::char_traits<char>::eof()) {
            in.setstate(std::ios::eofbit);
            return !line.empty();
        }
        if (c == '\n') return true;
        if (line.size() == kMaxLineBytes)
            throw std::runtime_error(lineError(path, n, "longer than " +
                                                            std::to_string(kMaxLineBytes >> 10) +
                                                            " KiB (not a text file of lines?)"));
        line.push_back(char(c));
    }
}
}  // namespace

void forEachDataLine(const std::string& path,
                     const std::function<void(int, const std::vector<std::string>&)>& fn) {
    // (an ifstream opens a folder and then fails to read: "error reading '<folder>'")
    if (std::filesystem::is_directory(path))
        throw std::runtime_error("'" + path + "' is a folder, not a file");
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open '" + path + "'");
    std::string line;
    int n = 0;
    std::size_t data_lines = 0;
    while (readLineCapped(in, line, path, n + 1)) {
        ++n;
        // A UTF-8 byte-order mark (Windows editors write one) is not part of the first line.
        if (n == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
        // A NUL or other control byte (a file damaged, or not text): a file name holding a
        // NUL was opened cut at it, a different file, without a word. (Tabs and a Windows
        // line end's '\r' are white space.)
        for (const char ch : line) {
            const auto u = static_cast<unsigned char>(ch);
            if (u < 0x20 && u != '\t' && u != '\r' && u != '\v' && u != '\f') {
                char code[8];
                std::snprintf(code, sizeof code, "0x%02x", u);
                throw std::runtime_error(lineError(
                    path, n, std::string("control byte ") + code + " (not a text file?)"));
            }
        }
        // A comment: from a '#' that starts the line or a word ("# note" after the values), not
        // one inside a file name ("take#2.png"), which the TUM tools read as part of it.
        for (std::size_t hash = line.find('#'); hash != std::string::npos;
             hash = line.find('#', hash + 1))
            if (hash == 0 || std::isspace(static_cast<unsigned char>(line[hash - 1]))) {
                line.resize(hash);
                break;
            }
        std::istringstream ss(line);
        std::vector<std::string> tokens;
        for (std::string t; ss >> t;) tokens.push_back(t);
        if (tokens.empty()) continue;
        if (++data_lines > kMaxDataLines)
            throw std::runtime_error(lineError(path, n,
                                               "more than " + std::to_string(kMaxDataLines) +
                                                   " data lines (28 hours at 100 Hz)"));
        fn(n, tokens);
    }
    if (in.bad()) throw std::runtime_error("error reading '" + path + "'");
}

double parseNumber(const std::string& token, const std::string& path, int line,
                   const std::string& what) {
    // Not std::stod: it also reads hexadecimal ("0x1p-3"), which the TUM tools' float()
    // refuses, and throws on an underflow ("1e-320"), which float() reads as ~0.
    double v = 0;
    if (!core::readFinite(token, v))
        throw std::runtime_error(lineError(path, line, what + " '" + token + "' is not a number"));
    return v;
}

std::string stampText(double t) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6f", t);
    return buf;
}

std::string stampNotAfter(double t, double previous, const std::string& text,
                          const std::string& kind) {
    return (t == previous ? "duplicate " : "unsorted ") + kind + " " + text;
}

std::string lineError(const std::string& path, int line, const std::string& msg) {
    return path + " line " + std::to_string(line) + ": " + msg;
}

WrittenFile openForWriting(const std::string& path) {
    WrittenFile f(std::fopen(path.c_str(), "w"), &std::fclose);
    if (!f) throw std::runtime_error("cannot write '" + path + "'");
    return f;
}

void closeWritten(WrittenFile& f, const std::string& error) {
    const bool failed = std::ferror(f.get()) != 0;
    if (std::fclose(f.release()) != 0 || failed) throw std::runtime_error(error);
}

void writePng(const std::string& path, const cv::Mat& image) {
    core::writePngWhole(path, image);
}

}  // namespace devslam::io::detail
