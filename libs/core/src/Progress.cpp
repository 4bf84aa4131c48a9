#include <devslam/core/Progress.h>

#include <unistd.h>

#include <algorithm>
#include <string>

namespace devslam::core {

ProgressBar::ProgressBar(std::string label, std::size_t total, std::FILE* out,
                         double min_interval_s)
    : label_(std::move(label)),
      total_(total),
      out_(out),
      min_interval_s_(min_interval_s),
      tty_(out != nullptr && isatty(fileno(out)) != 0),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

void ProgressBar::update(std::size_t done, const std::string& extra) {
    last_done_ = done;
    const auto now = std::chrono::steady_clock::now();
    // Non-terminals get a line every 10x the interval, so logs stay short.
    const double interval = tty_ ? min_interval_s_ : 10.0 * min_interval_s_ + 2.0;
    if (std::chrono::duration<double>(now - last_draw_).count() < interval) return;
    last_draw_ = now;
    draw(done, extra, false);
}

void ProgressBar::finish(const std::string& extra) {
    if (finished_) return;
    finished_ = true;
    draw(last_done_, extra, true);
}

void ProgressBar::draw(std::size_t done, const std::string& extra, bool final_line) {
    if (out_ == nullptr) return;
    shown_ = true;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double rate = elapsed > 0 ? static_cast<double>(done) / elapsed : 0.0;
    const double frac = total_ > 0 ? std::min(1.0, static_cast<double>(done) / total_) : 0.0;
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(frac * kWidth);
    std::string bar(filled, '#');
    bar += std::string(kWidth - filled, '.');
    if (tty_) std::fputc('\r', out_);
    std::fprintf(out_, "%s [%s] %zu/%zu %5.1f%% %.1f/s %s", label_.c_str(), bar.c_str(), done,
                 total_, 100.0 * frac, rate, extra.c_str());
    if (!tty_ || final_line) std::fputc('\n', out_);
    std::fflush(out_);
}

}  // namespace devslam::core
