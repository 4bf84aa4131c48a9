#include "ReplayReader.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace devslam::run {

ReplayReader::ReplayReader(io::RgbdReader& source, int passes, bool allow_damaged)
    : K_(source.intrinsics()) {
    if (passes < 1) throw std::invalid_argument("replay: passes must be >= 1");
    std::vector<std::string> undecodable;
    while (true) {
        std::optional<core::Frame> f;
        try {
            f = io::nextDecodable(source, allow_damaged, undecodable);
        } catch (const io::InputBroken&) {
            throw;
        } catch (const std::exception& e) {  // a frame that does not decode, without allow_damaged
            throw std::runtime_error(std::string(e.what()) +
                                     " (--replay reads every frame before the first is run; "
                                     "--allow-damaged leaves such frames out)");
        }
        if (!f) break;
        frames_.push_back(std::move(*f));
    }
    if (frames_.size() < 2)
        throw std::invalid_argument("--replay: " + source.describe() + " has " +
                                    std::to_string(frames_.size()) +
                                    " frame(s); a replay needs 2 or more");
    const double dt = (frames_.back().timestamp - frames_.front().timestamp) /
                      static_cast<double>(frames_.size() - 1);
    const auto n = frames_.size();
    for (int p = 0; p < passes; ++p) {
        for (std::size_t k = 0; k < n; ++k) {
            if (p > 0 && k == 0) continue;  // the turning frame is not repeated
            const std::size_t src = (p % 2 == 0) ? k : n - 1 - k;
            const double t = order_.empty()
                                 ? frames_[src].timestamp
                                 : (p == 0 ? frames_[src].timestamp : stamps_.back() + dt);
            order_.push_back(src);
            stamps_.push_back(t);
        }
    }
    if (const auto gt = source.groundTruth()) {
        core::Trajectory g;
        for (std::size_t i = 0; i < order_.size(); ++i) {
            const double t0 = frames_[order_[i]].timestamp;
            const auto it =
                std::min_element(gt->begin(), gt->end(), [&](const auto& a, const auto& b) {
                    return std::abs(a.t - t0) < std::abs(b.t - t0);
                });
            if (std::abs(it->t - t0) < 0.02) g.push_back({stamps_[i], it->pose});
        }
        gt_ = g;
    }
    damage_ = source.damage();
    if (!undecodable.empty())
        damage_ += (damage_.empty() ? "" : "; ") + std::to_string(undecodable.size()) +
                   " frame(s) that do not decode left out of the replay, the first: " +
                   undecodable.front();
    what_ = source.describe() + " replayed " + std::to_string(passes) + " passes (" +
            std::to_string(order_.size()) + " frames)";
}

std::optional<core::Frame> ReplayReader::next() {
    if (next_ >= order_.size()) return std::nullopt;
    core::Frame f = frames_[order_[next_]];
    f.bgr = f.bgr.clone();  // consumers may modify their frame
    f.depth = f.depth.clone();
    // Passes after the first get new stamps and no depth stamp, so depth-time compensation
    // is off for them (as it was when it read the stamp from the depth file's name, which
    // the replay cannot change; the long-run figures in RESULTS.md were made so).
    if (stamps_[next_] != f.timestamp) f.depth_timestamp.reset();
    f.timestamp = stamps_[next_];
    f.index = next_;
    ++next_;
    return f;
}

}  // namespace devslam::run
