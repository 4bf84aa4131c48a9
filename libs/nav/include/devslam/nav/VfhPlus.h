#pragma once
/// VFH+ (Ulrich & Borenstein, ICRA 1998) as a pure step function on a polar obstacle
/// histogram. Used by CHolonomicVFHPlus inside MRPT's TP-Space navigator, where sector k
/// has direction alpha_k = pi * (-1 + 2 (k + 0.5) / N) and obstacles[k] is the free
/// distance along that direction normalised by the PTG reference distance.
///
/// Stages (paper section numbers):
///   1. primary polar histogram (III.A): each sector's obstacle gives the magnitude
///      m = c^2 (a - b d^2) with a - b * window^2 = 0, enlarged to every sector within
///      gamma = asin(r_enl / d) (robot radius + safety distance),
///   2. binary histogram (III.B) with two thresholds tau_low < tau_high and hysteresis,
///   3. masked histogram (III.C): a blocked sector closer than mask_distance limits how
///      far the robot can turn to that side (its turning circle would hit it),
///   4. valleys -> candidates (III.D): wide valley (> s_max sectors): its two edges
///      shifted by s_max/2 and the target if inside; narrow valley: its centre,
///   5. cost g(c) = mu1 D(c, k_t) + mu2 D(c, k_heading) + mu3 D(c, k_prev), mu1 > mu2 + mu3,
///   6. speed v = v_max (1 - min(H_c, h_m) / h_m) (V.), slowed near the target.
///
/// Usage:
///   VfhPlusOptions opts;  VfhState state;
///   VfhOutput out = vfhPlusStep(input, state, opts);   // out.direction [rad], out.speed
///   state = out.next;                                  // carries hysteresis + previous dir
#include <cstdint>
#include <string>
#include <vector>

namespace mrpt::config {
class CConfigFileBase;
}

namespace devslam::nav {

/// VFH+ parameters (INI section [CHolonomicVFHPlus]). Distances marked [norm] are in
/// units of the PTG reference distance (1.0 = ref_distance metres).
struct VfhPlusOptions {
    double window = 0.6;               ///< [norm] active window radius: farther obstacles ignored
    double certainty = 1.0;            ///< [-] c: certainty of a sensed TP-obstacle (1 = sure)
    double enlargement_radius = 0.10;  ///< [m] r_r + d_s beyond the PTG's own robot shape
    double tau_low = 0.35;             ///< [-] below: free (binary histogram)
    double tau_high = 0.55;            ///< [-] above: blocked; in between keeps previous
    double min_free_distance = 0.10;   ///< [norm] closer obstacles always block the sector
    double mask_distance = 0.05;       ///< [norm] blocked sectors closer limit turning past them
    int wide_valley_sectors = 16;      ///< [sectors] s_max
    double mu1 = 5.0;                  ///< [-] weight: distance to target direction
    double mu2 = 2.0;                  ///< [-] weight: distance to current heading
    double mu3 = 2.0;                  ///< [-] weight: distance to previous direction
    double hm = 1.2;                   ///< [-] h_m: density at which the speed would reach 0
    double min_speed_ratio = 0.25;     ///< [-] floor of the obstacle slow-down factor
    double target_slowdown_distance = 0.15;  ///< [norm] slow down closer than this to target

    /// Reads [section] keys (snake_case); throws std::invalid_argument on unknown keys or
    /// bad values, naming `source`.
    void loadFromConfigFile(const mrpt::config::CConfigFileBase& c, const std::string& section,
                            const std::string& source = "INI");
    void saveToConfigFile(mrpt::config::CConfigFileBase& c, const std::string& section) const;
    void validate() const;
};

struct VfhInput {
    std::vector<double> obstacles;   ///< [norm] free distance per sector, k=0 -> alpha=-pi
    double target_x = 1.0;           ///< [norm] target in TP-Space (x ahead)
    double target_y = 0.0;           ///< [norm]
    double ref_distance = 1.0;       ///< [m] metres per normalised unit
    double max_obstacle_dist = 1.0;  ///< [norm] values >= this mean "no obstacle"
    double max_speed = 1.0;          ///< [norm/s] speed for a free path
    bool slow_near_target = true;
};

/// State carried between steps (binary histogram hysteresis and previous direction).
struct VfhState {
    std::vector<uint8_t> binary;  ///< previous binary histogram (1 = blocked)
    int prev_sector = -1;         ///< previously chosen sector, -1 if none
};

struct VfhOutput {
    int sector = -1;              ///< chosen sector, -1 if every direction is blocked
    double direction = 0.0;       ///< [rad] alpha of the chosen sector (0 if none)
    double speed = 0.0;           ///< [norm/s] in [0, max_speed]
    int target_sector = 0;        ///< sector of the target direction
    double target_density = 0.0;  ///< primary histogram value toward the target
    std::vector<double> primary;  ///< primary polar histogram H^p
    std::vector<uint8_t> binary;  ///< binary histogram H^b (1 = blocked)
    std::vector<uint8_t> masked;  ///< masked histogram H^m (1 = blocked)
    std::vector<int> candidates;  ///< candidate sectors
    std::vector<double> cost;     ///< cost of each candidate (same order)
    VfhState next;                ///< state to pass to the next step
};

/// Sector index of direction `alpha` [rad] among n sectors spanning [-pi, pi).
[[nodiscard]] int vfhSectorOf(double alpha, int n);
/// Direction [rad] of sector k among n.
[[nodiscard]] double vfhSectorAngle(int k, int n);

/// One VFH+ step. Pure: same inputs, same output. Throws std::invalid_argument for an
/// empty histogram.
[[nodiscard]] VfhOutput vfhPlusStep(const VfhInput& in, const VfhState& state,
                                    const VfhPlusOptions& opts);

}  // namespace devslam::nav
