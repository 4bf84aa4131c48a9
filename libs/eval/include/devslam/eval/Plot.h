#pragma once
/// A minimal 2D line/scatter plot on an OpenCV canvas: axes with ticks and labels, equal or
/// free aspect. Enough for trajectory figures without a plotting dependency (none is in
/// Debian's C++ set that would not pull in Python or Qt).
///
/// Usage:
///   devslam::eval::Plot p(cv::Rect(0, 0, 600, 450), "top view", "x [m]", "y [m]");
///   p.fit(xs, ys); p.equalAspect();
///   p.line(canvas, xs, ys, cv::Scalar(0, 0, 0));

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace devslam::eval {

class Plot {
  public:
    Plot(cv::Rect area, std::string title, std::string xlabel, std::string ylabel);
    /// Grows the data range to include these values.
    void fit(const std::vector<double>& xs, const std::vector<double>& ys);
    /// Expands the smaller range so that one metre is as long on both axes.
    void equalAspect();
    /// Draws the frame, ticks, labels and title (call once, before or after the data).
    void axes(cv::Mat& canvas) const;
    void line(cv::Mat& canvas, const std::vector<double>& xs, const std::vector<double>& ys,
              const cv::Scalar& bgr, int thickness = 1) const;
    void points(cv::Mat& canvas, const std::vector<double>& xs, const std::vector<double>& ys,
                const std::vector<cv::Scalar>& bgr, int radius = 2) const;
    /// Draws the items (a line in their colour, then the label) on a white box in the corner
    /// of the plot that covers the fewest of the points (avoid_xs, avoid_ys), in data units:
    /// top left, top right, bottom left, bottom right, the first on a tie.
    void legend(cv::Mat& canvas, const std::vector<std::pair<std::string, cv::Scalar>>& items,
                const std::vector<double>& avoid_xs = {},
                const std::vector<double>& avoid_ys = {}) const;
    [[nodiscard]] cv::Point toPixel(double x, double y) const;

  private:
    cv::Rect area_, inner_;
    std::string title_, xlabel_, ylabel_;
    double x0_ = 1e300, x1_ = -1e300, y0_ = 1e300, y1_ = -1e300;
};

/// `text` shortened from the front ("...end") to at most `width` pixels in Plot's font at
/// `scale`: a title that names a long path keeps its end (the file, and what is shown).
[[nodiscard]] std::string fitTextFromTheFront(const std::string& text, int width, double scale);

/// Draws a title in Plot's font and ink, baseline starting at `origin`, shortened from the
/// front (fitTextFromTheFront) to at most `width` pixels.
void drawTitle(cv::Mat& canvas, const std::string& text, cv::Point origin, int width,
               double scale);

/// Blue (0) to red (1) colour ramp, BGR.
[[nodiscard]] cv::Scalar heatColour(double t);

}  // namespace devslam::eval
