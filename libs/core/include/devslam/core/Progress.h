#pragma once
/// A one-line progress bar for long jobs, written to a stream (stderr by default), with the
/// processing rate. Redraws at most every `min_interval_s` seconds, and prints plain lines
/// instead of a bar when the stream is not a terminal (CI logs stay readable).
///
/// Usage:
///   devslam::core::ProgressBar bar("tracking", n_frames);
///   for (...) { ...; bar.update(i + 1); }
///   bar.finish();
/// Not thread-safe.

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <string>

namespace devslam::core {

class ProgressBar {
  public:
    ProgressBar(std::string label, std::size_t total, std::FILE* out = stderr,
                double min_interval_s = 0.25);
    void update(std::size_t done, const std::string& extra = {});
    void finish(const std::string& extra = {});
    /// Whether a line has been drawn (update() draws only after the interval).
    [[nodiscard]] bool shown() const { return shown_; }

  private:
    void draw(std::size_t done, const std::string& extra, bool final_line);
    std::string label_;
    std::size_t total_;
    std::FILE* out_;
    double min_interval_s_;
    bool tty_;
    std::chrono::steady_clock::time_point start_, last_draw_;
    std::size_t last_done_ = 0;
    bool finished_ = false;
    bool shown_ = false;
};

}  // namespace devslam::core
