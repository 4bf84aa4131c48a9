#pragma once
/// An input with ground truth from a file of its own (`devslam-run --groundtruth FILE`): a
/// rawlog holds none, and the TUM rawlogs MRPT publishes come with it beside them. Everything
/// but the ground truth is the wrapped reader's; a TUM folder's groundtruth.txt is replaced.
#include <devslam/io/RgbdReader.h>

#include <memory>
#include <string>
#include <utility>

namespace devslam::run {

class GivenTruthReader final : public io::RgbdReader {
  public:
    GivenTruthReader(std::unique_ptr<io::RgbdReader> source, core::Trajectory truth,
                     std::string truth_path)
        : source_(std::move(source)),
          truth_(std::move(truth)),
          truth_path_(std::move(truth_path)) {}
    [[nodiscard]] std::optional<core::Frame> next() override { return source_->next(); }
    [[nodiscard]] std::optional<std::size_t> size() const override { return source_->size(); }
    [[nodiscard]] std::optional<core::Trajectory> groundTruth() const override { return truth_; }
    [[nodiscard]] core::CameraIntrinsics intrinsics() const override {
        return source_->intrinsics();
    }
    [[nodiscard]] std::string describe() const override {
        return source_->describe() + " (ground truth: " + truth_path_ + ")";
    }
    [[nodiscard]] std::string damage() const override { return source_->damage(); }

  private:
    std::unique_ptr<io::RgbdReader> source_;
    core::Trajectory truth_;
    std::string truth_path_;
};

}  // namespace devslam::run
