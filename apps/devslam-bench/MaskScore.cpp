#include "MaskScore.h"

#include <opencv2/core.hpp>

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace devslam::bench {

std::map<std::string, std::vector<PersonEntry>> readPersons(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open '" + path + "'");
    std::map<std::string, std::vector<PersonEntry>> out;
    std::string line;
    for (int n = 1; std::getline(in, line); ++n) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream ss(line);
        std::string t, state;
        PersonEntry p;
        int x = 0, y = 0, w = 0, h = 0;
        if (!(ss >> t >> p.id >> p.name >> state >> x >> y >> w >> h >> p.visible_pixels) ||
            (state != "moving" && state != "static"))
            throw std::runtime_error(
                path + " line " + std::to_string(n) +
                ": expected 'timestamp id name moving|static x y w h visible_pixels'");
        p.moving = state == "moving";
        out[t].push_back(p);
    }
    return out;
}

void MaskScore::add(const cv::Mat& mask, const cv::Mat& labels,
                    const std::vector<PersonEntry>& persons, int min_pixels) {
    const bool has_mask = !mask.empty();
    if (has_mask) masked_px += cv::countNonZero(mask);
    for (const auto& p : persons) {
        const cv::Mat mine = labels == p.id;
        const double vis = cv::countNonZero(mine);
        const double hit = has_mask ? cv::countNonZero(mine & mask) : 0.0;
        if (p.moving) {
            moving_px += vis;
            moving_px_masked += hit;
        }
        if (vis < min_pixels) continue;
        const bool masked = hit >= 0.5 * vis;
        if (p.moving) {
            ++moving_instances;
            moving_masked += masked;
        } else {
            ++static_instances;
            static_masked += masked;
        }
    }
}

double MaskScore::movingRecall() const {
    return moving_instances ? double(moving_masked) / moving_instances : 0.0;
}
double MaskScore::staticMasked() const {
    return static_instances ? double(static_masked) / static_instances : 0.0;
}
double MaskScore::movingAreaRecall() const {
    return moving_px > 0 ? moving_px_masked / moving_px : 0.0;
}
double MaskScore::precision() const {
    return masked_px > 0 ? moving_px_masked / masked_px : 0.0;
}

}  // namespace devslam::bench
