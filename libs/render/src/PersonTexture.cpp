#include <devslam/render/PersonTexture.h>

#include <devslam/core/Picture.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <stdexcept>

namespace devslam::render {

cv::Mat cutPersonTexture(const cv::Mat& bgr, const cv::Rect& box, int iterations) {
    if (bgr.empty() || bgr.type() != CV_8UC3)
        throw std::invalid_argument("cutPersonTexture: need a non-empty CV_8UC3 image");
    const cv::Rect img(0, 0, bgr.cols, bgr.rows);
    if (box.area() <= 0 || (box & img) != box)
        throw std::invalid_argument("cutPersonTexture: box is empty or outside the image");
    cv::setRNGSeed(12345);  // grabCut's GMM initialisation uses k-means with the global RNG
    cv::Mat mask(bgr.size(), CV_8UC1, cv::Scalar(cv::GC_BGD)), bgd, fgd;
    cv::grabCut(bgr, mask, box, bgd, fgd, iterations, cv::GC_INIT_WITH_RECT);
    cv::Mat fg = (mask == cv::GC_FGD) | (mask == cv::GC_PR_FGD);
    // Keep the largest connected blob (the person), drop specks.
    cv::Mat lab, stats, cent;
    const int n = cv::connectedComponentsWithStats(fg, lab, stats, cent, 8);
    int best = 0, best_area = 0;
    for (int i = 1; i < n; ++i)
        if (stats.at<int>(i, cv::CC_STAT_AREA) > best_area) {
            best_area = stats.at<int>(i, cv::CC_STAT_AREA);
            best = i;
        }
    if (best_area < 0.05 * box.area())
        throw std::invalid_argument("cutPersonTexture: the cut kept less than 5% of the box");
    fg = lab == best;
    // Crop to the person's own extent, so that the texture's bottom row is the feet.
    const cv::Rect tight = cv::boundingRect(fg) & box;
    cv::Mat bgra;
    cv::cvtColor(bgr(tight), bgra, cv::COLOR_BGR2BGRA);
    std::vector<cv::Mat> ch;
    cv::split(bgra, ch);
    ch[3] = fg(tight).clone();
    cv::merge(ch, bgra);
    return bgra;
}

std::string textureTooLarge(const cv::Mat& img, const std::string& path) {
    if (img.cols <= kMaxTextureSide && img.rows <= kMaxTextureSide) return "";
    return "texture '" + path + "' is " + std::to_string(img.cols) + "x" +
           std::to_string(img.rows) + " px; at most " + std::to_string(kMaxTextureSide) +
           " px per side (the frames are 640x480, and larger photos cost gigabytes): "
           "downscale it";
}

PersonTexture loadPersonTexture(const std::string& path, int cell_px) {
    std::string why;
    const cv::Mat img = core::readImage(path, cv::IMREAD_UNCHANGED, why);
    if (img.empty()) throw std::runtime_error("person texture '" + path + "': cannot read" + why);
    if (const auto big = textureTooLarge(img, path); !big.empty())
        throw std::runtime_error("person " + big);
    if (img.type() != CV_8UC4)
        throw std::runtime_error("person texture '" + path +
                                 "': need an RGBA PNG (alpha = person)");
    if (cell_px < 1) throw std::invalid_argument("loadPersonTexture: cell_px must be >= 1");
    PersonTexture t;
    t.cell_px = cell_px;
    std::vector<cv::Mat> ch;
    cv::split(img, ch);
    const cv::Mat alpha = ch[3];
    cv::merge(std::vector<cv::Mat>{ch[0], ch[1], ch[2]}, t.bgr);
    // Fill background texels with nearby person colours so that cell borders do not show
    // the photo's background.
    const cv::Mat holes = alpha < 128;
    if (cv::countNonZero(holes) > 0 && cv::countNonZero(~holes) > 0) {
        // Each background texel takes the colour of its nearest person texel.
        cv::Mat dist, label;
        cv::distanceTransform(holes, dist, label, cv::DIST_L2, cv::DIST_MASK_5,
                              cv::DIST_LABEL_PIXEL);
        std::vector<cv::Point> source(std::size_t(alpha.total()) + 1);
        for (int v = 0; v < alpha.rows; ++v)
            for (int u = 0; u < alpha.cols; ++u)
                if (!holes.at<uchar>(v, u)) source[std::size_t(label.at<int>(v, u))] = {u, v};
        const cv::Mat src = t.bgr.clone();
        for (int v = 0; v < alpha.rows; ++v)
            for (int u = 0; u < alpha.cols; ++u)
                if (holes.at<uchar>(v, u))
                    t.bgr.at<cv::Vec3b>(v, u) =
                        src.at<cv::Vec3b>(source[std::size_t(label.at<int>(v, u))]);
    }
    const int rows = (alpha.rows + cell_px - 1) / cell_px,
              cols = (alpha.cols + cell_px - 1) / cell_px;
    t.cell_mask = cv::Mat(rows, cols, CV_8UC1, cv::Scalar(0));
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) {
            const cv::Rect cell = cv::Rect(c * cell_px, r * cell_px, cell_px, cell_px) &
                                  cv::Rect(0, 0, alpha.cols, alpha.rows);
            const double opaque = cv::countNonZero(alpha(cell) >= 128);
            if (opaque * 2 > cell.area()) t.cell_mask.at<uchar>(r, c) = 255;
        }
    return t;
}

}  // namespace devslam::render
