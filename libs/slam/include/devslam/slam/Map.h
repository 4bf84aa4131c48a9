#pragma once
/// The map: keyframes and landmarks in containers keyed by ids (no pointer webs).
///
/// Usage:
///   devslam::slam::Map map;
///   KeyframeId k = map.addKeyframe(std::move(kf));
///   LandmarkId l = map.addLandmark(p_w, descriptor, color, k, kp_index);
/// Not thread-safe.
#include <devslam/slam/Types.h>

#include <map>
#include <unordered_map>

namespace devslam::slam {

class Map {
  public:
    /// Takes the keyframe, assigns its id (returned) and sizes landmark_of_kp.
    KeyframeId addKeyframe(Keyframe kf);
    /// New landmark first observed by keypoint `kp` of keyframe `kf` (which must exist).
    LandmarkId addLandmark(const Eigen::Vector3d& p_w, const cv::Mat& descriptor,
                           const cv::Vec3b& color, KeyframeId kf, int kp);
    /// Records that keypoint `kp` of keyframe `kf` observes landmark `lm` (both must exist).
    void addObservation(LandmarkId lm, KeyframeId kf, int kp);
    /// Removes a landmark and every keyframe's reference to it.
    void removeLandmark(LandmarkId lm);
    /// Removes one observation (keyframe kf, keypoint kp), if present.
    void removeObservation(LandmarkId lm, KeyframeId kf, int kp);
    /// Removes a keyframe (which must exist) and its observations. A landmark no other
    /// keyframe observes goes with it; one it anchored (ref_kf), observed there or not, is
    /// anchored to its oldest remaining observer. Returns the number of landmarks removed.
    int removeKeyframe(KeyframeId id);
    /// Fraction of the landmarks keyframe `id` observes that at least `min_observers` other
    /// keyframes observe at the same pyramid level, one coarser, or finer (ORB-SLAM2's
    /// redundancy test); 0 for a keyframe without landmarks.
    [[nodiscard]] double redundantFraction(KeyframeId id, int min_observers) const;

    [[nodiscard]] const std::map<KeyframeId, Keyframe>& keyframes() const { return keyframes_; }
    [[nodiscard]] std::map<KeyframeId, Keyframe>& keyframes() { return keyframes_; }
    [[nodiscard]] const std::unordered_map<LandmarkId, Landmark>& landmarks() const {
        return landmarks_;
    }
    [[nodiscard]] std::unordered_map<LandmarkId, Landmark>& landmarks() { return landmarks_; }
    [[nodiscard]] Keyframe& keyframe(KeyframeId id);
    [[nodiscard]] const Keyframe& keyframe(KeyframeId id) const;
    [[nodiscard]] Landmark* landmark(LandmarkId id);
    [[nodiscard]] const Landmark* landmark(LandmarkId id) const;
    /// The last `n` keyframes by id (newest last).
    [[nodiscard]] std::vector<KeyframeId> lastKeyframes(std::size_t n) const;
    /// Landmarks observed by any of `kfs` (unique, in first-seen order).
    [[nodiscard]] std::vector<LandmarkId> landmarksOf(const std::vector<KeyframeId>& kfs) const;
    [[nodiscard]] bool empty() const { return keyframes_.empty(); }
    /// Approximate heap bytes held by keyframes and landmarks (for memory reports).
    [[nodiscard]] std::size_t approxBytes() const;

  private:
    std::map<KeyframeId, Keyframe> keyframes_;
    std::unordered_map<LandmarkId, Landmark> landmarks_;
    KeyframeId next_kf_ = 0;
    LandmarkId next_lm_ = 0;
};

}  // namespace devslam::slam
