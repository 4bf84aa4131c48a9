#pragma once
// Private helpers: iterate over the data lines of a whitespace-separated text file with
// '#' comments (the TUM list and trajectory formats), and write one whole.

#include <opencv2/core/mat.hpp>

#include <cstddef>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace devslam::io::detail {

/// The longest line forEachDataLine reads [bytes]: a TUM line is under 100.
inline constexpr std::size_t kMaxLineBytes = std::size_t(64) << 10;
/// The most data lines forEachDataLine reads: 28 hours of ground truth at 100 Hz.
inline constexpr std::size_t kMaxDataLines = 10'000'000;

/// Calls fn(line_number, tokens) for each non-empty, non-comment line. Throws
/// std::runtime_error "cannot open '<path>'" if the file cannot be read, naming the line of
/// one longer than kMaxLineBytes or past kMaxDataLines data lines. (A pipe is read as a
/// file: devslam-eval <(...) works.)
void forEachDataLine(const std::string& path,
                     const std::function<void(int, const std::vector<std::string>&)>& fn);

/// Strict number parse (the whole token must be a finite number); throws
/// std::runtime_error "<path> line N: <what> '<token>' is not a number".
[[nodiscard]] double parseNumber(const std::string& token, const std::string& path, int line,
                                 const std::string& what);

[[nodiscard]] std::string lineError(const std::string& path, int line, const std::string& msg);

/// A stamp as TUM writes it: "%.6f" (microseconds).
[[nodiscard]] std::string stampText(double t);

/// Why `t` (written `text`) may not follow `previous` in a sequence whose stamps must increase:
/// "duplicate <kind> <text>" or "unsorted <kind> <text>" (TUM lists, rawlog observations and
/// written TUM folders word it alike).
[[nodiscard]] std::string stampNotAfter(double t, double previous, const std::string& text,
                                        const std::string& kind = "timestamp");

using WrittenFile = std::unique_ptr<std::FILE, int (*)(std::FILE*)>;

/// fopen(path, "w"); throws std::runtime_error "cannot write '<path>'".
[[nodiscard]] WrittenFile openForWriting(const std::string& path);

/// Closes `f` (released whatever happens) and throws std::runtime_error(error) if any write
/// failed: the last buffer goes out at fclose, so a full disk is found there, not by ferror
/// before.
void closeWritten(WrittenFile& f, const std::string& error);

/// Writes a frame's PNG whole or not at all (core::writePngWhole); throws std::runtime_error
/// "cannot write '<path>': <why>". (cv::imwrite did not check fclose(), where stdio's last
/// buffer goes out: a disk that filled there left a cut PNG behind a success.)
void writePng(const std::string& path, const cv::Mat& image);

}  // namespace devslam::io::detail
