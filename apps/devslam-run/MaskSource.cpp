#include "MaskSource.h"

#include <stdexcept>
#include <utility>

#include <devslam/core/Config.h>

#ifdef DEVSLAM_HAVE_DYNAMIC
#include <devslam/detect/PersonDetector.h>
#include <devslam/dynamic/DynamicObjectFilter.h>
#endif

namespace devslam::run {

namespace {
class TruthMask final : public MaskSource {
  public:
    TruthMask(eval::PersonTruth truth, int margin) : truth_(std::move(truth)), margin_(margin) {}
    MaskStep step(const core::Frame& frame, const std::optional<Eigen::Isometry3d>&) override {
        MaskStep s;
        s.mask = truth_.walkerMask(frame.timestamp, margin_, frame.bgr.size());
        return s;
    }
    void reset() override {}
    std::string describe() const override {
        return "renderer truth: walking people's pixels dilated by " + std::to_string(margin_) +
               " px (diagnostic)";
    }

  private:
    eval::PersonTruth truth_;
    int margin_;
};

#ifndef DEVSLAM_HAVE_DYNAMIC
class NoMask final : public MaskSource {
  public:
    MaskStep step(const core::Frame&, const std::optional<Eigen::Isometry3d>&) override {
        return {};
    }
    void reset() override {}
    std::string describe() const override { return "none (no detector)"; }
};
#endif

#ifdef DEVSLAM_HAVE_DYNAMIC
class FilterMask final : public MaskSource {
  public:
    explicit FilterMask(std::unique_ptr<dynamic::DynamicObjectFilter> f) : filter_(std::move(f)) {}
    MaskStep step(const core::Frame& frame,
                  const std::optional<Eigen::Isometry3d>& prior) override {
        auto out = filter_->step(frame, prior);
        MaskStep s;
        s.mask = std::move(out.mask);
        s.detect_ms = out.detect_ms;
        s.filter_ms = out.filter_ms;
        s.detector_ran = out.detector_ran;
        s.n_boxes = static_cast<int>(out.boxes.size());
        for (const auto& b : out.boxes) {
            s.n_moving += b.state == dynamic::BoxState::Moving ? 1 : 0;
            s.boxes.push_back({b.box, dynamic::toString(b.state)});
        }
        s.T_prev_cur_refined = out.T_prev_cur_refined;
        s.static_people = std::move(out.static_people);
        s.static_weight = filter_->options().static_person_weight;
        s.static_gate_exponent = filter_->options().static_person_gate;
        return s;
    }
    void reset() override { filter_->reset(); }
    int minFrameSide() const override { return filter_->options().minFrameSide(); }
    std::string describe() const override {
        return "dynamic filter, mode " + dynamic::toString(filter_->options().mode);
    }

  private:
    std::unique_ptr<dynamic::DynamicObjectFilter> filter_;
};
#endif
}  // namespace

void requireMode(const std::string& mode) {
    if (mode != "none" && mode != "all_persons" && mode != "dynamic" && mode != "truth")
        throw std::invalid_argument("unknown mode '" + mode +
                                    "' (known: none, all_persons, dynamic, truth)");
}

std::unique_ptr<MaskSource> makeMaskSource(const std::string& mode,
                                           const mrpt::config::CConfigFileBase& cfg,
                                           const std::string& input) {
    requireMode(mode);
    if (mode == "truth") {
#ifdef DEVSLAM_HAVE_DYNAMIC
        // The whole section, as the other modes read it: a mistyped key is an error here too.
        dynamic::DynamicObjectFilter::Options o;
        o.loadFromConfig(cfg);
        const int margin = o.mask_margin;
        (void)detect::makeDetector(cfg, "detector");  // ... and [detector], as the other modes
#else
        const int margin = core::readInt(cfg, "dynamic_filter", "mask_margin", 10);
        if (margin < 0)
            throw std::invalid_argument("[dynamic_filter] mask_margin: must be >= 0, got " +
                                        std::to_string(margin));
#endif
        auto truth = eval::PersonTruth::open(input);
        if (!truth)
            throw std::invalid_argument(
                "mode 'truth' needs the renderer's person truth (persons.txt and labels/), "
                "which '" +
                input + "' does not have");
        return std::make_unique<TruthMask>(std::move(*truth), margin);
    }
#ifdef DEVSLAM_HAVE_DYNAMIC
    auto filter = dynamic::makeFilterFromConfig(cfg, dynamic::parseMaskMode(mode));
    return std::make_unique<FilterMask>(std::move(filter));
#else
    (void)cfg;
    if (mode != "none")
        throw std::runtime_error("mode '" + mode +
                                 "' needs devslam::dynamic, which this build does not have");
    return std::make_unique<NoMask>();
#endif
}

}  // namespace devslam::run
