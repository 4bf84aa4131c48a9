#include <devslam/core/Config.h>
#include <devslam/nav/VfhPlus.h>

#include <mrpt/config/CConfigFileBase.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace devslam::nav {

namespace {
constexpr const char* kKeys[] = {"window",
                                 "certainty",
                                 "enlargement_radius",
                                 "tau_low",
                                 "tau_high",
                                 "min_free_distance",
                                 "mask_distance",
                                 "wide_valley_sectors",
                                 "mu1",
                                 "mu2",
                                 "mu3",
                                 "hm",
                                 "min_speed_ratio",
                                 "target_slowdown_distance"};
}  // namespace

void VfhPlusOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& c,
                                        const std::string& s, const std::string& source) {
    core::requireKnownKeys(c, s, std::vector<std::string>(std::begin(kKeys), std::end(kKeys)),
                           source);
    window = core::readDouble(c, s, "window", window);
    certainty = core::readDouble(c, s, "certainty", certainty);
    enlargement_radius = core::readDouble(c, s, "enlargement_radius", enlargement_radius);
    tau_low = core::readDouble(c, s, "tau_low", tau_low);
    tau_high = core::readDouble(c, s, "tau_high", tau_high);
    min_free_distance = core::readDouble(c, s, "min_free_distance", min_free_distance);
    mask_distance = core::readDouble(c, s, "mask_distance", mask_distance);
    wide_valley_sectors = core::readInt(c, s, "wide_valley_sectors", wide_valley_sectors);
    mu1 = core::readDouble(c, s, "mu1", mu1);
    mu2 = core::readDouble(c, s, "mu2", mu2);
    mu3 = core::readDouble(c, s, "mu3", mu3);
    hm = core::readDouble(c, s, "hm", hm);
    min_speed_ratio = core::readDouble(c, s, "min_speed_ratio", min_speed_ratio);
    target_slowdown_distance =
        core::readDouble(c, s, "target_slowdown_distance", target_slowdown_distance);
    validate();
}

void VfhPlusOptions::saveToConfigFile(mrpt::config::CConfigFileBase& c,
                                      const std::string& s) const {
    core::writeKey(c, s, "window", window);
    core::writeKey(c, s, "certainty", certainty);
    core::writeKey(c, s, "enlargement_radius", enlargement_radius);
    core::writeKey(c, s, "tau_low", tau_low);
    core::writeKey(c, s, "tau_high", tau_high);
    core::writeKey(c, s, "min_free_distance", min_free_distance);
    core::writeKey(c, s, "mask_distance", mask_distance);
    core::writeKey(c, s, "wide_valley_sectors", wide_valley_sectors);
    core::writeKey(c, s, "mu1", mu1);
    core::writeKey(c, s, "mu2", mu2);
    core::writeKey(c, s, "mu3", mu3);
    core::writeKey(c, s, "hm", hm);
    core::writeKey(c, s, "min_speed_ratio", min_speed_ratio);
    core::writeKey(c, s, "target_slowdown_distance", target_slowdown_distance);
}

void VfhPlusOptions::validate() const {
    const std::string sec = "CHolonomicVFHPlus";
    core::requireValue(window > 0 && window <= 1.0, sec, "window", "must be in (0, 1]");
    core::requireValue(certainty > 0 && certainty <= 1.0, sec, "certainty", "must be in (0, 1]");
    // (1e9 m blocked every sector: a timeout standing, no hint)
    core::requireValue(enlargement_radius >= 0 && enlargement_radius <= 5, sec,
                       "enlargement_radius", "must be in [0, 5] m");
    core::requireValue(tau_low >= 0 && tau_low <= tau_high, sec, "tau_low",
                       "must satisfy 0 <= tau_low <= tau_high");
    core::requireValue(min_free_distance >= 0 && min_free_distance < 1, sec, "min_free_distance",
                       "must be in [0, 1)");
    core::requireValue(mask_distance >= 0 && mask_distance < 1, sec, "mask_distance",
                       "must be in [0, 1)");
    core::requireValue(wide_valley_sectors >= 2, sec, "wide_valley_sectors", "must be >= 2");
    core::requireValue(mu1 > mu2 + mu3, sec, "mu1",
                       "must be greater than mu2 + mu3 (Ulrich & Borenstein's condition)");
    core::requireValue(mu2 >= 0 && mu3 >= 0, sec, "mu2", "mu2 and mu3 must be >= 0");
    core::requireValue(hm > 0, sec, "hm", "must be > 0");
    core::requireValue(min_speed_ratio >= 0 && min_speed_ratio <= 1, sec, "min_speed_ratio",
                       "must be in [0, 1]");
    core::requireValue(target_slowdown_distance >= 0, sec, "target_slowdown_distance",
                       "must be >= 0");
}

int vfhSectorOf(double alpha, int n) {
    const int k = static_cast<int>(std::round(0.5 * (n * (1.0 + alpha / M_PI) - 1.0)));
    return std::clamp(k, 0, n - 1);
}

double vfhSectorAngle(int k, int n) {
    return M_PI * (-1.0 + 2.0 * (k + 0.5) / n);
}

VfhOutput vfhPlusStep(const VfhInput& in, const VfhState& state, const VfhPlusOptions& o) {
    const int n = static_cast<int>(in.obstacles.size());
    if (n == 0) throw std::invalid_argument("vfhPlusStep: empty obstacle histogram");
    const double max_d = in.max_obstacle_dist > 0 ? in.max_obstacle_dist : 1.0;
    const double target_dist = std::hypot(in.target_x, in.target_y);
    VfhOutput out;
    out.target_sector = vfhSectorOf(std::atan2(in.target_y, in.target_x), n);
    const int k_heading = vfhSectorOf(0.0, n);
    const double sector_width = 2.0 * M_PI / n;

    // Active window: obstacles beyond the target (plus a margin) cannot block the way to it.
    const double window =
        std::clamp(target_dist + 0.1, std::min(o.window, 2.0 * o.min_free_distance), o.window);

    std::vector<double> d(n);
    for (int k = 0; k < n; k++) d[k] = std::clamp(in.obstacles[k] / max_d, 0.0, 1.0);

    // 1) primary polar histogram, enlarged by r_enl (Ulrich & Borenstein eq. 2-5)
    out.primary.assign(n, 0.0);
    const double c2 = o.certainty * o.certainty;
    for (int j = 0; j < n; j++) {
        if (d[j] >= window) continue;
        const double m = c2 * (1.0 - (d[j] * d[j]) / (window * window));
        const double d_m = d[j] * in.ref_distance;
        const double gamma =
            d_m > o.enlargement_radius ? std::asin(o.enlargement_radius / d_m) : M_PI / 2;
        const int span = static_cast<int>(std::floor(gamma / sector_width + 0.5));
        for (int k = std::max(0, j - span); k <= std::min(n - 1, j + span); k++)
            out.primary[k] = std::max(out.primary[k], m);
    }
    out.target_density = out.primary[out.target_sector];

    // 2) binary histogram with two-threshold hysteresis (eq. 7)
    out.binary.assign(n, 0);
    const bool have_prev = state.binary.size() == static_cast<size_t>(n);
    for (int k = 0; k < n; k++) {
        uint8_t b;
        if (out.primary[k] > o.tau_high)
            b = 1;
        else if (out.primary[k] < o.tau_low)
            b = 0;
        else
            b = have_prev ? state.binary[k] : 0;
        if (d[k] < o.min_free_distance) b = 1;
        out.binary[k] = b;
    }

    // 3) masked histogram: a close blocked sector limits turning beyond it (eq. 8-9)
    out.masked = out.binary;
    if (o.mask_distance > 0) {
        for (int k = k_heading + 1; k < n; k++)
            if (out.binary[k] && d[k] < o.mask_distance) {
                std::fill(out.masked.begin() + k, out.masked.end(), 1);
                break;
            }
        for (int k = k_heading - 1; k >= 0; k--)
            if (out.binary[k] && d[k] < o.mask_distance) {
                std::fill(out.masked.begin(), out.masked.begin() + k + 1, 1);
                break;
            }
    }

    // 4) valleys -> candidate directions
    const int s_max = o.wide_valley_sectors;
    for (int k = 0; k < n;) {
        if (out.masked[k]) {
            k++;
            continue;
        }
        const int k_r = k;
        while (k < n && !out.masked[k]) k++;
        const int k_l = k - 1;
        const int len = k_l - k_r + 1;
        if (len > s_max) {
            // A valley's side at the histogram's end (+-pi) is no obstacle: the TP-space
            // directions do not wrap there (MRPT's C PTGs' paths at +-pi differ), and keeping
            // s_max/2 off it left a target near +-pi out of reach (the robot stopped 0.33 m
            // from a goal it had passed, the target at sector 4 of 121, every candidate >= 8).
            const int c_r = k_r == 0 ? 0 : k_r + s_max / 2;
            const int c_l = k_l == n - 1 ? n - 1 : k_l - s_max / 2;
            out.candidates.push_back(c_r);
            out.candidates.push_back(c_l);
            if (out.target_sector > c_r && out.target_sector < c_l)
                out.candidates.push_back(out.target_sector);
        } else {
            out.candidates.push_back((k_r + k_l) / 2);
        }
    }

    // 5) cost function (eq. 10)
    double best_cost = std::numeric_limits<double>::infinity();
    for (int c : out.candidates) {
        double cost = o.mu1 * std::abs(c - out.target_sector) + o.mu2 * std::abs(c - k_heading);
        if (state.prev_sector >= 0) cost += o.mu3 * std::abs(c - state.prev_sector);
        out.cost.push_back(cost);
        if (cost < best_cost) {
            best_cost = cost;
            out.sector = c;
        }
    }
    out.next.binary = out.binary;
    out.next.prev_sector = out.sector;
    if (out.sector < 0) return out;  // all blocked: stop, keep direction 0

    // 6) speed (section V): slower in dense sectors and near the target
    out.direction = vfhSectorAngle(out.sector, n);
    const double h_c = std::min(out.primary[out.sector], o.hm);
    double v = in.max_speed * std::max(o.min_speed_ratio, 1.0 - h_c / o.hm);
    if (in.slow_near_target && o.target_slowdown_distance > 0 &&
        target_dist < o.target_slowdown_distance)
        v *= target_dist / o.target_slowdown_distance;
    out.speed = std::clamp(v, 0.0, in.max_speed);
    return out;
}

}  // namespace devslam::nav
