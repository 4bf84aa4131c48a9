#include <devslam/core/GzFile.h>

#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
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
    bool failed = true;  // (not `why.empty()`: an exception with an empty text is a failure too)
    try {
        GzOutputStream s(part, 1, kind);
        try {
            write(s);
            s.close();
            failed = false;
        } catch (const std::exception& e) {
            why = !s.lastError().empty() ? s.lastError() : innermostMessage(e.what());
        }
    } catch (const std::exception& e) {  // not made (its folder is not there, ...)
        why = std::strerror(errno != 0 ? errno : EIO);
    }
    if (failed && why.empty()) why = "the writer failed without saying why";
    std::error_code ec;
    if (!failed) {
        std::filesystem::rename(part, path, ec);
        if (!ec) return;
        why = ec.message();
    }
    std::filesystem::remove(part, ec);
    throw std::runtime_error("cannot write " + kind + " '" + path + "': " + why);
}

// Written out with zlib's inflate: no zlib call tells where gzread's last member ended. It
// follows gzread's rules (gz_look, gz_decomp in zlib's gzread.c), so that `damage` is the text
// gzread's gzerror gives, without reading the file a second time: a file not starting with
// the gzip magic is no gzip (gzread copies it as it is); after a member, the magic starts the
// next one, and anything else ends the stream (gzread drops it: `trailing` says what it was).
GzipCheck gzipCheck(const std::string& path, GzipCheckControl* control) {
    GzipCheck out;
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (f == nullptr) {
        out.damage = "cannot open";
        return out;
    }
    z_stream s{};
    if (inflateInit2(&s, 15 + 16) != Z_OK) {  // gzip only, as gzread
        std::fclose(f);
        out.damage = "out of memory";
        return out;
    }
    std::vector<unsigned char> in(1 << 16), out_buf(1 << 16);
    std::uint64_t read = 0;  // bytes of the file read into `in` so far
    bool read_failed = false;
    int read_errno = 0;       // errno of the read that failed
    const auto topUp = [&] {  // keeps what is left of `in` and reads more after it
        std::memmove(in.data(), s.next_in, s.avail_in);
        errno = 0;
        std::size_t n = std::fread(in.data() + s.avail_in, 1, in.size() - s.avail_in, f);
        if (std::ferror(f) != 0) {  // as gzread: what came with the failed read is not used
            if (!read_failed) read_errno = errno != 0 ? errno : EIO;
            read_failed = true;
            n = 0;
        }
        read += n;
        if (control != nullptr) control->bytes_read.store(read, std::memory_order_relaxed);
        s.next_in = in.data();
        s.avail_in += static_cast<uInt>(n);
        return n > 0;
    };
    const auto readError = [&] { return std::string(std::strerror(read_errno)); };
    s.next_in = in.data();
    const auto gzipMagicNext = [&] {
        if (s.avail_in < 2) topUp();
        return s.avail_in >= 2 && s.next_in[0] == 0x1f && s.next_in[1] == 0x8b;
    };
    if (!gzipMagicNext()) {  // no gzip (an empty file, a plain rawlog): gzread copies it
        if (read_failed) out.damage = readError();
    } else {
        for (;;) {
            if (control != nullptr && control->stop.load(std::memory_order_relaxed)) {
                out.stopped = true;
                break;
            }
            if (s.avail_in == 0 && !topUp()) {
                out.damage = read_failed ? readError() : "unexpected end of file";
                break;
            }
            s.next_out = out_buf.data();
            s.avail_out = static_cast<uInt>(out_buf.size());
            const int rc = inflate(&s, Z_NO_FLUSH);
            if (rc == Z_STREAM_END) {
                const std::uint64_t end = read - s.avail_in;  // where this member ends
                if (gzipMagicNext()) {
                    inflateReset(&s);
                    continue;
                }
                if (read_failed) {
                    out.damage = readError();
                } else if (s.avail_in > 0) {
                    const long size = std::fseek(f, 0, SEEK_END) == 0 ? std::ftell(f) : -1L;
                    const std::uint64_t extra = size > 0 && std::uint64_t(size) > end
                                                    ? std::uint64_t(size) - end
                                                    : std::uint64_t(s.avail_in);  // (at least)
                    out.trailing = std::to_string(extra) + (extra == 1 ? " byte" : " bytes") +
                                   " after the end of its gzip data at byte " +
                                   std::to_string(end) + (extra == 1 ? " is" : " are") +
                                   " no gzip stream (another file appended, or damage)";
                }
                break;
            }
            if (rc == Z_DATA_ERROR) {
                out.damage = s.msg != nullptr ? s.msg : "compressed data error";
                break;
            }
            if (rc == Z_MEM_ERROR) {
                out.damage = "out of memory";
                break;
            }
            if (rc == Z_STREAM_ERROR || rc == Z_NEED_DICT) {
                out.damage = "internal error: inflate stream corrupt";
                break;
            }
        }
    }
    inflateEnd(&s);
    std::fclose(f);
    return out;
}

std::string gzipDamage(const std::string& path) {
    return gzipCheck(path).damage;
}

std::string innermostMessage(const std::string& what) {
    const auto lineAt = [&](std::size_t b) { return what.substr(b, what.find('\n', b) - b); };
    std::size_t at = 0;  // where the chosen line starts
    // An exception MRPT wraps without a "Message:" (OpenCV's, from inside CImage) has the
    // banner as its first line and the text on the next: the banner alone said nothing.
    if (lineAt(0) == "==== MRPT exception ====" && what.find('\n') != std::string::npos)
        at = what.find('\n') + 1;
    for (std::size_t p = what.find("Message:"); p != std::string::npos;
         p = what.find("Message:", p + 1)) {
        const std::size_t b = what.find_first_not_of(' ', p + 8);
        if (b == std::string::npos || what[b] == '\n') continue;  // an empty "Message:"
        at = b;
    }
    std::string best = lineAt(at);
    if (best.empty()) {  // nothing after the banner: the first line of text there is
        const std::size_t b = what.find_first_not_of("\n");
        best = b == std::string::npos ? std::string() : lineAt(b);
    }
    // MRPT's ASSERT_GT_(a,b) and kin write the values on the next two lines: the message
    // ended "failed with", and the values were lost.
    if (const std::string tail = "failed with";
        best.size() >= tail.size() &&
        best.compare(best.size() - tail.size(), tail.size(), tail) == 0)
        for (std::size_t b = what.find('\n', at), k = 0; b != std::string::npos && k < 2; ++k) {
            const std::string value = lineAt(b + 1);
            if (value.empty() || value.find('=') == std::string::npos) break;
            best += (k == 0 ? " " : ", ") + value;
            b = what.find('\n', b + 1);
        }
    // OpenCV's "OpenCV(4.6.0) ./modules/x.cpp:816: error: (-215:Assertion failed) ...": its
    // source line is of no use to the reader.
    if (best.rfind("OpenCV(", 0) == 0)
        if (const std::size_t e = best.find(": error: "); e != std::string::npos)
            best = "OpenCV: " + best.substr(e + 9);
    return best;
}

}  // namespace devslam::core
