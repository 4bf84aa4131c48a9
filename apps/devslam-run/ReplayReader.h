#pragma once
/// A longer sequence made from a short one: the frames played forward, backward, forward...
/// `passes` times with continuing timestamps (frame interval kept), with the ground truth
/// mapped the same way. For memory and long-run checks when only a short real sequence
/// ships. Holds every source frame in memory.
#include <devslam/io/RgbdReader.h>

#include <memory>
#include <vector>

namespace devslam::run {

class ReplayReader final : public io::RgbdReader {
  public:
    /// Reads all of `source`; throws std::invalid_argument for passes < 1 or < 2 frames. A
    /// frame that does not decode is left out with `allow_damaged` (damage() says so), else
    /// its error is thrown before any frame is run (with the hint of --allow-damaged);
    /// io::InputBroken (nothing after it can be read) is thrown as it is.
    ReplayReader(io::RgbdReader& source, int passes, bool allow_damaged = false);
    [[nodiscard]] std::optional<core::Frame> next() override;
    [[nodiscard]] std::optional<std::size_t> size() const override { return order_.size(); }
    [[nodiscard]] std::optional<core::Trajectory> groundTruth() const override { return gt_; }
    [[nodiscard]] core::CameraIntrinsics intrinsics() const override { return K_; }
    [[nodiscard]] std::string describe() const override { return what_; }
    [[nodiscard]] std::string damage() const override { return damage_; }

  private:
    std::vector<core::Frame> frames_;
    std::vector<std::size_t> order_;  ///< source index of each output frame
    std::vector<double> stamps_;      ///< output timestamps
    std::optional<core::Trajectory> gt_;
    core::CameraIntrinsics K_;
    std::string what_, damage_;
    std::size_t next_ = 0;
};

}  // namespace devslam::run
