#pragma once
/// VFH+ as an MRPT holonomic navigation method (MRPT's plugin naming, hence the C prefix).
///
/// Selected in an MRPT reactive-navigation INI by
///   [CAbstractPTGBasedReactive]  holonomic_method = CHolonomicVFHPlus
/// with its parameters in [CHolonomicVFHPlus] (see VfhPlusOptions). The class lives in a
/// static library, so the executable must call registerNavClasses() once before loading
/// the navigator config (a static initializer would be dropped by the linker).
///
/// Usage:
///   devslam::nav::registerNavClasses();
///   mrpt::nav::CReactiveNavigationSystem nav(robot);
///   nav.loadConfigFile(cfg);   // holonomic_method = CHolonomicVFHPlus
/// Not thread-safe (keeps the hysteresis state between calls).
#include <devslam/nav/VfhPlus.h>

#include <mrpt/nav/holonomic/CAbstractHolonomicReactiveMethod.h>
#include <mrpt/nav/holonomic/CHolonomicLogFileRecord.h>

namespace devslam::nav {

/// Per-step record written into MRPT's navlog (viewable with navlog-viewer).
class CLogFileRecord_VFHPlus : public mrpt::nav::CHolonomicLogFileRecord {
    DEFINE_SERIALIZABLE(CLogFileRecord_VFHPlus, devslam::nav)
  public:
    int selected_sector = -1;
    int target_sector = -1;
    double target_density = 0;        ///< primary histogram toward the target
    std::vector<double> primary;      ///< H^p per sector
    std::vector<uint8_t> binary;      ///< H^b (1 = blocked)
    std::vector<uint8_t> masked;      ///< H^m (1 = blocked)
    std::vector<int32_t> candidates;  ///< candidate sectors
};

class CHolonomicVFHPlus : public mrpt::nav::CAbstractHolonomicReactiveMethod {
    DEFINE_SERIALIZABLE(CHolonomicVFHPlus, devslam::nav)
  public:
    /// Default-constructible (MRPT's class factory needs it); loads `cfg` if given.
    explicit CHolonomicVFHPlus(const mrpt::config::CConfigFileBase* cfg = nullptr);

    void navigate(const NavInput& ni, NavOutput& no) override;
    void initialize(const mrpt::config::CConfigFileBase& c) override;
    void saveConfigFile(mrpt::config::CConfigFileBase& c) const override;
    double getTargetApproachSlowDownDistance() const override {
        return options.target_slowdown_distance;
    }
    void setTargetApproachSlowDownDistance(const double d) override {
        options.target_slowdown_distance = d;
    }

    VfhPlusOptions options;
    /// The last step's full output (for tests and the replanning trigger).
    [[nodiscard]] const VfhOutput& lastOutput() const { return last_; }
    /// How many times navigate() has run: MRPT runs a PTG's method only on the steps where
    /// the target is in that PTG's domain, so lastOutput() may be an older step's.
    [[nodiscard]] std::uint64_t steps() const { return steps_; }

  private:
    VfhState state_;
    VfhOutput last_;
    std::uint64_t steps_ = 0;
};

/// Registers CHolonomicVFHPlus and its log record in MRPT's class registry. Idempotent;
/// call once from main() (or a test) before creating a navigator.
void registerNavClasses();

/// Throws std::invalid_argument "<what>: unknown holonomic method 'X' (known: ...)" unless
/// MRPT's factory makes a holonomic method of that class name (MRPT's navigator would
/// otherwise stop with a stack trace once the run has started). Registers ours first.
void requireHolonomicMethod(const std::string& name, const std::string& what);

}  // namespace devslam::nav
