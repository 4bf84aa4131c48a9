#pragma once
/// Two helpers for files MRPT writes through gzip streams (rawlogs, `.gridmap` archives):
/// MRPT's gz reader stops quietly at a file's cut end, and its exceptions nest their texts
/// several levels deep under banners and stack traces.
///
/// Usage:
///   if (auto d = devslam::core::gzipDamage(path); !d.empty()) throw ...(path + ": " + d);
///   catch (const std::exception& e) { ... devslam::core::innermostMessage(e.what()) ... }
#include <mrpt/io/CStream.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

namespace devslam::core {

/// A gzip file written through MRPT's CStream interface (an archive's `<<`), as MRPT's
/// CFileGZOutputStream writes it (gzopen "wb<level>"), but whose errors are not lost: that
/// one's close() ignores what gzclose() returns, and the last compressed block and the gzip
/// trailer leave zlib's buffers only there, so a disk that filled at the end gave a file cut
/// short without a word. `kind` names the file in messages ("rawlog" -> "cannot write rawlog
/// 'PATH'").
class GzOutputStream : public mrpt::io::CStream {
  public:
    /// Throws std::runtime_error "cannot write <kind> '<path>': <why>" when it cannot be made;
    /// `exclusive`: also when the file is there (made with O_EXCL, so of two writers starting
    /// at once only one gets it: "File exists").
    GzOutputStream(const std::string& path, int level, std::string kind, bool exclusive = false);
    ~GzOutputStream() override;
    GzOutputStream(const GzOutputStream&) = delete;
    GzOutputStream& operator=(const GzOutputStream&) = delete;
    size_t Read(void*, size_t) override;  ///< throws std::logic_error: open for writing
    /// Whole or the bytes before the error (MRPT's archive throws when fewer bytes than asked
    /// were written); lastError() says why.
    size_t Write(const void* buf, size_t count) override;
    uint64_t Seek(int64_t, TSeekOrigin) override;  ///< throws std::logic_error
    uint64_t getTotalBytesCount() const override { return written_; }
    uint64_t getPosition() const override { return written_; }
    /// Flushes zlib's buffers and the trailer; throws std::runtime_error "error writing
    /// <kind> '<path>': its end was not written (disk full?), the file is cut short" if they
    /// could not be written. Once only; the destructor closes it otherwise (silently).
    void close();
    /// Why the last write or close failed, as zlib or the system says ("No space left on
    /// device"); "" when none did.
    [[nodiscard]] const std::string& lastError() const { return error_; }
    [[nodiscard]] const std::string& path() const { return path_; }

  private:
    void noteError();
    std::string path_, kind_, error_;
    void* gz_ = nullptr;  // gzFile, kept out of this header with <zlib.h>
    uint64_t written_ = 0;
};

/// Writes a gzip file whole or not at all: `write` fills a GzOutputStream into `path`.part,
/// which is closed and renamed over `path`. Throws std::runtime_error "cannot write <kind>
/// '<path>': <why>" (the .part removed, `path` left as it was) when any of it fails. For
/// MRPT's archives (`archiveFrom(s) << object`), which CFileGZOutputStream cut short on a
/// full disk without a word.
void writeGzFileWhole(const std::string& path, const std::string& kind,
                      const std::function<void(mrpt::io::CStream&)>& write);

/// What is wrong with a gzip file, found in one pass through it (inflating a file is its
/// whole cost: 5 s for a 700 MB rawlog here).
struct GzipCheck {
    /// A gzip stream cut short decodes cleanly up to the cut, and MRPT's stream reports a plain
    /// end of file there (or, reading an archive, nothing at all); only zlib knows the trailer
    /// is missing. "" when the file is a complete gzip stream or no gzip at all (a plain
    /// rawlog, which zlib's reader passes through); otherwise the text zlib's gzread would give
    /// ("unexpected end of file", "incorrect data check", "cannot open", ...).
    std::string damage;
    /// What follows the last gzip member, if anything does: zlib (and so MRPT's stream) reads
    /// members one after another and ends quietly at anything else, so a second rawlog
    /// appended with a damaged header, or junk after a whole one, lost its frames without a
    /// word. "" when the file is gzip members alone, no gzip at all, or damaged inside;
    /// else "N bytes after the end of its gzip data at byte B are no gzip stream (...)".
    std::string trailing;
    /// Ended early by `stop` (below): the other fields then mean nothing.
    bool stopped = false;
};

/// What a caller on another thread sees of a gzipCheck and may do to it.
struct GzipCheckControl {
    /// Set true to end the reading early (a check run beside another reader that failed
    /// first); the check then returns with `stopped`.
    std::atomic<bool> stop{false};
    /// Bytes of the file read so far (for a progress bar).
    std::atomic<std::uint64_t> bytes_read{0};
};

/// Reads the file at `path` through once; `control` may be null.
[[nodiscard]] GzipCheck gzipCheck(const std::string& path, GzipCheckControl* control = nullptr);

/// `gzipCheck(path).damage`.
[[nodiscard]] std::string gzipDamage(const std::string& path);

/// The innermost non-empty "Message:" line of an MRPT exception text (its first line when
/// it has none, the line after MRPT's banner when that is the first; an OpenCV error without
/// OpenCV's source location).
[[nodiscard]] std::string innermostMessage(const std::string& what);

}  // namespace devslam::core
