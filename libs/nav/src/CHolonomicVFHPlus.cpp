#include <devslam/nav/CHolonomicVFHPlus.h>

#include <mrpt/nav/tpspace/CParameterizedTrajectoryGenerator.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/serialization/stl_serialization.h>

namespace devslam::nav {

IMPLEMENTS_SERIALIZABLE(CHolonomicVFHPlus, mrpt::nav::CAbstractHolonomicReactiveMethod,
                        devslam::nav)
IMPLEMENTS_SERIALIZABLE(CLogFileRecord_VFHPlus, mrpt::nav::CHolonomicLogFileRecord, devslam::nav)

void registerNavClasses() {
    static const bool done = [] {
        mrpt::rtti::registerClass(CLASS_ID(devslam::nav::CHolonomicVFHPlus));
        mrpt::rtti::registerClass(CLASS_ID(devslam::nav::CLogFileRecord_VFHPlus));
        return true;
    }();
    (void)done;
}

void requireHolonomicMethod(const std::string& name, const std::string& what) {
    registerNavClasses();
    if (!mrpt::nav::CAbstractHolonomicReactiveMethod::Factory(name))
        throw std::invalid_argument(what + ": unknown holonomic method '" + name +
                                    "' (known: CHolonomicVFHPlus, CHolonomicND, "
                                    "CHolonomicFullEval, CHolonomicVFF)");
}

CHolonomicVFHPlus::CHolonomicVFHPlus(const mrpt::config::CConfigFileBase* cfg)
    : CAbstractHolonomicReactiveMethod("CHolonomicVFHPlus") {
    if (cfg) initialize(*cfg);
}

void CHolonomicVFHPlus::initialize(const mrpt::config::CConfigFileBase& c) {
    options.loadFromConfigFile(c, getConfigFileSectionName(), "navigator INI");
}

void CHolonomicVFHPlus::saveConfigFile(mrpt::config::CConfigFileBase& c) const {
    options.saveToConfigFile(c, getConfigFileSectionName());
}

void CHolonomicVFHPlus::navigate(const NavInput& ni, NavOutput& no) {
    if (ni.targets.empty()) throw std::invalid_argument("CHolonomicVFHPlus: no target given");
    VfhInput in;
    in.obstacles = ni.obstacles;
    in.target_x = ni.targets.back().x;  // last = highest priority
    in.target_y = ni.targets.back().y;
    in.max_obstacle_dist = ni.maxObstacleDist;
    in.max_speed = ni.maxRobotSpeed;
    in.slow_near_target = m_enableApproachTargetSlowDown;
    const auto ptg = getAssociatedPTG();
    in.ref_distance = ptg ? ptg->getRefDistance() : 1.0;

    last_ = vfhPlusStep(in, state_, options);
    state_ = last_.next;
    ++steps_;

    auto log = std::make_shared<CLogFileRecord_VFHPlus>();
    log->selected_sector = last_.sector;
    log->target_sector = last_.target_sector;
    log->target_density = last_.target_density;
    log->primary = last_.primary;
    log->binary = last_.binary;
    log->masked = last_.masked;
    log->candidates.assign(last_.candidates.begin(), last_.candidates.end());
    // Final-stage score per direction -> MRPT's "holo_stage_eval" variable.
    std::vector<double> eval(in.obstacles.size(), 0.0);
    for (size_t i = 0; i < last_.candidates.size(); i++)
        eval[last_.candidates[i]] = 1.0 / (1.0 + 0.1 * last_.cost[i]);
    log->dirs_eval = {std::move(eval)};

    no.desiredDirection = last_.direction;
    no.desiredSpeed = last_.speed;
    no.logRecord = log;
}

uint8_t CHolonomicVFHPlus::serializeGetVersion() const {
    return 0;
}
void CHolonomicVFHPlus::serializeTo(mrpt::serialization::CArchive& out) const {
    const auto& o = options;
    out << o.window << o.certainty << o.enlargement_radius << o.tau_low << o.tau_high
        << o.min_free_distance << o.mask_distance << int32_t(o.wide_valley_sectors) << o.mu1
        << o.mu2 << o.mu3 << o.hm << o.min_speed_ratio << o.target_slowdown_distance;
}
void CHolonomicVFHPlus::serializeFrom(mrpt::serialization::CArchive& in, uint8_t version) {
    auto& o = options;
    int32_t s_max = 0;
    switch (version) {
        case 0:
            in >> o.window >> o.certainty >> o.enlargement_radius >> o.tau_low >> o.tau_high >>
                o.min_free_distance >> o.mask_distance >> s_max >> o.mu1 >> o.mu2 >> o.mu3 >>
                o.hm >> o.min_speed_ratio >> o.target_slowdown_distance;
            o.wide_valley_sectors = s_max;
            break;
        default:
            MRPT_THROW_UNKNOWN_SERIALIZATION_VERSION(version);
    }
}

uint8_t CLogFileRecord_VFHPlus::serializeGetVersion() const {
    return 0;
}
void CLogFileRecord_VFHPlus::serializeTo(mrpt::serialization::CArchive& out) const {
    out << int32_t(selected_sector) << int32_t(target_sector) << target_density << primary << binary
        << masked << candidates << dirs_eval;
}
void CLogFileRecord_VFHPlus::serializeFrom(mrpt::serialization::CArchive& in, uint8_t version) {
    int32_t sel = 0, trg = 0;
    switch (version) {
        case 0:
            in >> sel >> trg >> target_density >> primary >> binary >> masked >> candidates >>
                dirs_eval;
            selected_sector = sel;
            target_sector = trg;
            break;
        default:
            MRPT_THROW_UNKNOWN_SERIALIZATION_VERSION(version);
    }
}

}  // namespace devslam::nav
