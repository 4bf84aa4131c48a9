#include <devslam/core/GzFile.h>

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <utility>
#include <vector>

namespace devslam::core {

GzOutputStream::GzOutputStream(const std::string& path, int level, std::string kind, bool exclusive)
    : path_(path), kind_(std::move(kind)) {
    errno = 0;
    gz_ = gzopen(path.c_str(), ("wb" + std::to_string(level) + (exclusive ? "x" : "")).c_str());
    if (gz_ == nullptr)
        throw std::runtime_error("cannot write " + kind_ + " '" + path + "'" +
                                 (errno != 0 ? std::string(": ") + std::strerror(errno) : ""));
}

GzOutputStream::~GzOutputStream() {
    if (gz_ != nullptr) gzclose(static_cast<gzFile>(gz_));
}

size_t GzOutputStream::Read(void*, size_t) {
    throw std::logic_error(kind_ + " '" + path_ + "' is open for writing");
}

size_t GzOutputStream::Write(const void* buf, size_t count) {
    if (gz_ == nullptr) return 0;
    const auto* p = static_cast<const char*>(buf);
    size_t done = 0;
    while (done < count) {
        const auto chunk = static_cast<unsigned>(std::min<size_t>(count - done, 1u << 30));
        errno = 0;
        const int n = gzwrite(static_cast<gzFile>(gz_), p + done, chunk);
        if (n <= 0) {
            noteError();
            break;
        }
        done += static_cast<size_t>(n);
    }
    written_ += done;
    return done;
}

uint64_t GzOutputStream::Seek(int64_t, TSeekOrigin) {
    throw std::logic_error(kind_ + " '" + path_ + "': a gzip stream cannot seek");
}

void GzOutputStream::noteError() {
    int err = Z_OK;
    const char* msg = gzerror(static_cast<gzFile>(gz_), &err);
    error_ = err == Z_ERRNO ? std::strerror(errno) : (msg != nullptr ? msg : "write error");
}

void GzOutputStream::close() {
    if (gz_ == nullptr) return;
    errno = 0;
    const int rc = gzclose(static_cast<gzFile>(std::exchange(gz_, nullptr)));
    if (rc == Z_OK) return;
    if (error_.empty()) error_ = rc == Z_ERRNO && errno != 0 ? std::strerror(errno) : "write error";
    throw std::runtime_error("error writing " + kind_ + " '" + path_ +
                             "': its end was not written (disk full?), the file is cut short");
}

void writeGzFileWhole(const std::string& path, const std::string& kind,
                      const std::function<void(mrpt::io::CStream&)>& write) {
    const std::string part = path + ".part";
    std::string why;
    try {
        GzOutputStream s(part, 1, kind);
        try {
            write(s);
            s.close();
        } catch (const std::exception& e) {
            why = !s.lastError().empty() ? s.lastError() : innermostMessage(e.what());
        }
    } catch (const std::exception& e) {  // not made (its folder is not there, ...)
        why = std::strerror(errno != 0 ? errno : EIO);
    }
    std::error_code ec;
    if (why.empty()) {
        std::filesystem::rename(part, path, ec);
        if (!ec) return;
        why = ec.message();
    }
    std::filesystem::remove(part, ec);
    throw std::runtime_error("cannot write " + kind + " '" + path + "': " + why);
}

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
    // zlib puts the file's name in front ("<path>: unexpected end of file"): the callers name
    // it themselves, and it came out twice.
    if (out.rfind(path + ": ", 0) == 0) out.erase(0, path.size() + 2);
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
