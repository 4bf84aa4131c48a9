#include <devslam/eval/Plot.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

namespace devslam::eval {

namespace {
constexpr int kMarginLeft = 70, kMarginRight = 15, kMarginTop = 30, kMarginBottom = 45;
const cv::Scalar kInk(40, 40, 40);
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

double niceStep(double range, int target_ticks) {
    const double raw = range / std::max(1, target_ticks);
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    for (double m : {1.0, 2.0, 5.0, 10.0})
        if (raw <= m * mag) return m * mag;
    return 10 * mag;
}

}  // namespace

std::string fitTextFromTheFront(const std::string& text, int width, double scale) {
    const auto wide = [&](const std::string& t) {
        int base = 0;
        return cv::getTextSize(t, kFont, scale, 1, &base).width > width;
    };
    if (!wide(text)) return text;
    for (std::size_t cut = 1; cut < text.size(); ++cut)
        if (std::string t = "..." + text.substr(cut); !wide(t)) return t;
    return {};
}

void drawTitle(cv::Mat& canvas, const std::string& text, cv::Point origin, int width,
               double scale) {
    cv::putText(canvas, fitTextFromTheFront(text, width, scale), origin, kFont, scale, kInk, 1,
                cv::LINE_AA);
}

cv::Scalar heatColour(double t) {
    t = std::clamp(t, 0.0, 1.0);
    return {255 * (1 - t), 60 + 100 * (1 - std::abs(2 * t - 1)), 255 * t};
}

Plot::Plot(cv::Rect area, std::string title, std::string xlabel, std::string ylabel)
    : area_(area),
      inner_(area.x + kMarginLeft, area.y + kMarginTop, area.width - kMarginLeft - kMarginRight,
             area.height - kMarginTop - kMarginBottom),
      title_(std::move(title)),
      xlabel_(std::move(xlabel)),
      ylabel_(std::move(ylabel)) {}

void Plot::fit(const std::vector<double>& xs, const std::vector<double>& ys) {
    for (double x : xs) x0_ = std::min(x0_, x), x1_ = std::max(x1_, x);
    for (double y : ys) y0_ = std::min(y0_, y), y1_ = std::max(y1_, y);
    if (x0_ > x1_) x0_ = 0, x1_ = 1;
    if (y0_ > y1_) y0_ = 0, y1_ = 1;
    constexpr double kMinRange = 1e-3;
    if (x1_ - x0_ < kMinRange) x0_ -= kMinRange, x1_ += kMinRange;
    if (y1_ - y0_ < kMinRange) y0_ -= kMinRange, y1_ += kMinRange;
}

void Plot::equalAspect() {
    const double sx = (x1_ - x0_) / inner_.width, sy = (y1_ - y0_) / inner_.height;
    const double s = std::max(sx, sy);
    const double cx = 0.5 * (x0_ + x1_), cy = 0.5 * (y0_ + y1_);
    x0_ = cx - 0.5 * s * inner_.width, x1_ = cx + 0.5 * s * inner_.width;
    y0_ = cy - 0.5 * s * inner_.height, y1_ = cy + 0.5 * s * inner_.height;
}

cv::Point Plot::toPixel(double x, double y) const {
    const double u = inner_.x + (x - x0_) / (x1_ - x0_) * inner_.width;
    const double v = inner_.y + inner_.height - (y - y0_) / (y1_ - y0_) * inner_.height;
    return {static_cast<int>(std::lround(u)), static_cast<int>(std::lround(v))};
}

void Plot::axes(cv::Mat& c) const {
    cv::rectangle(c, inner_, kInk, 1);
    const auto font = kFont;
    char buf[32];
    const double sx = niceStep(x1_ - x0_, 6), sy = niceStep(y1_ - y0_, 6);
    // Ticks by index, at most 64: "x += step" stops advancing where the step is below the
    // float spacing of x (coordinates far from 0 with a tiny range) and would never end.
    const double x_first = std::ceil(x0_ / sx) * sx, y_first = std::ceil(y0_ / sy) * sy;
    for (int i = 0; i < 64 && x_first + i * sx <= x1_; ++i) {
        const double x = x_first + i * sx;
        const cv::Point p = toPixel(x, y0_);
        cv::line(c, p, p + cv::Point(0, 5), kInk);
        cv::line(c, {p.x, inner_.y}, {p.x, p.y}, cv::Scalar(225, 225, 225));
        std::snprintf(buf, sizeof buf, "%.3g", std::abs(x) < 1e-12 ? 0.0 : x);
        cv::putText(c, buf, p + cv::Point(-15, 20), font, 0.4, kInk, 1, cv::LINE_AA);
    }
    for (int i = 0; i < 64 && y_first + i * sy <= y1_; ++i) {
        const double y = y_first + i * sy;
        const cv::Point p = toPixel(x0_, y);
        cv::line(c, p, p - cv::Point(5, 0), kInk);
        cv::line(c, p, {inner_.x + inner_.width, p.y}, cv::Scalar(225, 225, 225));
        std::snprintf(buf, sizeof buf, "%.3g", std::abs(y) < 1e-12 ? 0.0 : y);
        cv::putText(c, buf, p + cv::Point(-55, 4), font, 0.4, kInk, 1, cv::LINE_AA);
    }
    cv::rectangle(c, inner_, kInk, 1);
    // The title stays inside the plot's area.
    drawTitle(c, title_, {inner_.x, area_.y + 20}, area_.x + area_.width - 4 - inner_.x, 0.55);
    cv::putText(c, xlabel_, {inner_.x + inner_.width / 2 - 20, area_.y + area_.height - 8}, font,
                0.45, kInk, 1, cv::LINE_AA);
    cv::putText(c, ylabel_, {area_.x + 2, inner_.y - 8}, font, 0.45, kInk, 1, cv::LINE_AA);
}

void Plot::line(cv::Mat& c, const std::vector<double>& xs, const std::vector<double>& ys,
                const cv::Scalar& bgr, int thickness) const {
    std::vector<cv::Point> pts;
    for (std::size_t i = 0; i < std::min(xs.size(), ys.size()); ++i)
        pts.push_back(toPixel(xs[i], ys[i]));
    if (pts.size() >= 2) cv::polylines(c, pts, false, bgr, thickness, cv::LINE_AA);
}

void Plot::points(cv::Mat& c, const std::vector<double>& xs, const std::vector<double>& ys,
                  const std::vector<cv::Scalar>& bgr, int radius) const {
    for (std::size_t i = 0; i < std::min(xs.size(), ys.size()); ++i)
        cv::circle(c, toPixel(xs[i], ys[i]), radius,
                   bgr.empty() ? kInk : bgr[std::min(i, bgr.size() - 1)], cv::FILLED, cv::LINE_AA);
}

void Plot::legend(cv::Mat& c, const std::vector<std::pair<std::string, cv::Scalar>>& items,
                  const std::vector<double>& avoid_xs, const std::vector<double>& avoid_ys) const {
    constexpr double kScale = 0.42;
    constexpr int kRow = 16, kMargin = 4;
    int text = 0;
    for (const auto& item : items)
        text = std::max(text,
                        cv::getTextSize(item.first, cv::FONT_HERSHEY_SIMPLEX, kScale, 1, nullptr)
                            .width);
    const cv::Size size(34 + text + 6, kRow * static_cast<int>(items.size()) + 6);
    const int left = inner_.x + kMargin, right = inner_.x + inner_.width - kMargin - size.width;
    const int top = inner_.y + kMargin, bottom = inner_.y + inner_.height - kMargin - size.height;
    const std::vector<cv::Rect> corners{{{left, top}, size},
                                        {{right, top}, size},
                                        {{left, bottom}, size},
                                        {{right, bottom}, size}};
    cv::Rect box = corners.front();
    std::size_t fewest = SIZE_MAX;
    for (const auto& r : corners) {
        std::size_t covered = 0;
        for (std::size_t i = 0; i < std::min(avoid_xs.size(), avoid_ys.size()); ++i)
            covered += r.contains(toPixel(avoid_xs[i], avoid_ys[i])) ? 1 : 0;
        if (covered < fewest) fewest = covered, box = r;
    }
    cv::rectangle(c, box, cv::Scalar(255, 255, 255), cv::FILLED);
    cv::rectangle(c, box, cv::Scalar(200, 200, 200), 1);
    int y = box.y + 15;
    for (const auto& [label, colour] : items) {
        cv::line(c, {box.x + 6, y - 4}, {box.x + 26, y - 4}, colour, 2, cv::LINE_AA);
        cv::putText(c, label, {box.x + 32, y}, cv::FONT_HERSHEY_SIMPLEX, kScale, kInk, 1,
                    cv::LINE_AA);
        y += kRow;
    }
}

}  // namespace devslam::eval
