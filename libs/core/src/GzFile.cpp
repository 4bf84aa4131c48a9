#include <devslam/core/GzFile.h>

#include <zlib.h>

#include <vector>

namespace devslam::core {

std::string gzipDamage(const std::string& path) {
    gzFile f = gzopen(path.c_str(), "rb");
    if (f == nullptr) return "cannot open";
    std::vector<char> buf(1 << 20);
    int n = 0;
    while ((n = gzread(f, buf.data(), static_cast<unsigned>(buf.size()))) > 0) {
    }
    int err = Z_OK;
    const char* msg = gzerror(f, &err);
    std::string out = (n < 0 || (err != Z_OK && err != Z_STREAM_END)) ? msg : "";
    gzclose(f);
    return out;
}

std::string innermostMessage(const std::string& what) {
    std::string best = what.substr(0, what.find('\n'));
    for (std::size_t p = what.find("Message:"); p != std::string::npos;
         p = what.find("Message:", p + 1)) {
        const std::size_t b = what.find_first_not_of(' ', p + 8);
        if (b == std::string::npos || what[b] == '\n') continue;  // an empty "Message:"
        best = what.substr(b, what.find('\n', b) - b);
    }
    return best;
}

}  // namespace devslam::core
