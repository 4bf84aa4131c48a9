#include <devslam/slam/Map.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <unordered_set>

namespace devslam::slam {

KeyframeId Map::addKeyframe(Keyframe kf) {
    kf.id = next_kf_++;
    kf.landmark_of_kp.assign(kf.features.size(), kNoId);
    const KeyframeId id = kf.id;
    keyframes_.emplace(id, std::move(kf));
    return id;
}

LandmarkId Map::addLandmark(const Eigen::Vector3d& p_w, const cv::Mat& descriptor,
                            const cv::Vec3b& color, KeyframeId kf, int kp) {
    Landmark lm;
    lm.id = next_lm_++;
    lm.p_w = p_w;
    lm.descriptor = descriptor.clone();
    lm.color = color;
    lm.ref_kf = kf;
    lm.created_kf = kf;
    const LandmarkId id = lm.id;
    landmarks_.emplace(id, std::move(lm));
    addObservation(id, kf, kp);
    return id;
}

void Map::addObservation(LandmarkId lm, KeyframeId kf, int kp) {
    Keyframe& k = keyframe(kf);
    Landmark* l = landmark(lm);
    if (!l) throw std::out_of_range("slam map: no landmark " + std::to_string(lm));
    if (kp < 0 || kp >= static_cast<int>(k.landmark_of_kp.size()))
        throw std::out_of_range("slam map: keyframe " + std::to_string(kf) + " has no keypoint " +
                                std::to_string(kp));
    if (k.landmark_of_kp[kp] != kNoId) removeObservation(k.landmark_of_kp[kp], kf, kp);
    k.landmark_of_kp[kp] = lm;
    l->observations.emplace_back(kf, kp);
}

void Map::removeObservation(LandmarkId lm, KeyframeId kf, int kp) {
    Landmark* l = landmark(lm);
    if (!l) return;
    auto& obs = l->observations;
    obs.erase(std::remove(obs.begin(), obs.end(), std::make_pair(kf, kp)), obs.end());
    auto it = keyframes_.find(kf);
    if (it != keyframes_.end() && kp >= 0 &&
        kp < static_cast<int>(it->second.landmark_of_kp.size()) &&
        it->second.landmark_of_kp[kp] == lm)
        it->second.landmark_of_kp[kp] = kNoId;
}

void Map::removeLandmark(LandmarkId lm) {
    auto it = landmarks_.find(lm);
    if (it == landmarks_.end()) return;
    for (const auto& [kf, kp] : it->second.observations) {
        auto k = keyframes_.find(kf);
        if (k != keyframes_.end() && k->second.landmark_of_kp[kp] == lm)
            k->second.landmark_of_kp[kp] = kNoId;
    }
    landmarks_.erase(it);
}

int Map::removeKeyframe(KeyframeId id) {
    const Keyframe& k = keyframe(id);
    int orphans = 0;
    for (std::size_t kp = 0; kp < k.landmark_of_kp.size(); ++kp) {
        const LandmarkId lm = k.landmark_of_kp[kp];
        Landmark* l = landmark(lm);
        if (!l) continue;
        removeObservation(lm, id, static_cast<int>(kp));
        if (l->observations.empty()) {
            landmarks_.erase(lm);
            ++orphans;
        }
    }
    // Re-anchored: every landmark it anchored, also one whose observation there local BA
    // dropped as an outlier (the keyframe no longer lists it). Such a landmark kept the
    // culled keyframe as its anchor, and a loop correction then left it where it was.
    for (auto& [lid, l] : landmarks_)
        if (l.ref_kf == id && !l.observations.empty())
            l.ref_kf = std::min_element(l.observations.begin(), l.observations.end())
                           ->first;  // the oldest observer
    keyframes_.erase(id);
    return orphans;
}

double Map::redundantFraction(KeyframeId id, int min_observers) const {
    const Keyframe& k = keyframe(id);
    int n = 0, redundant = 0;
    for (std::size_t kp = 0; kp < k.landmark_of_kp.size(); ++kp) {
        const Landmark* l = landmark(k.landmark_of_kp[kp]);
        if (!l) continue;
        ++n;
        // Seen as sharply elsewhere: at the same pyramid level, one coarser, or finer.
        const int level = k.features.keypoints[kp].octave;
        int others = 0;
        for (const auto& [kf, okp] : l->observations) {
            if (kf == id) continue;
            if (keyframe(kf).features.keypoints[static_cast<std::size_t>(okp)].octave <= level + 1)
                ++others;
            if (others >= min_observers) break;
        }
        if (others >= min_observers) ++redundant;
    }
    return n > 0 ? static_cast<double>(redundant) / n : 0.0;
}

Keyframe& Map::keyframe(KeyframeId id) {
    auto it = keyframes_.find(id);
    if (it == keyframes_.end())
        throw std::out_of_range("slam map: no keyframe " + std::to_string(id));
    return it->second;
}

const Keyframe& Map::keyframe(KeyframeId id) const {
    auto it = keyframes_.find(id);
    if (it == keyframes_.end())
        throw std::out_of_range("slam map: no keyframe " + std::to_string(id));
    return it->second;
}

Landmark* Map::landmark(LandmarkId id) {
    auto it = landmarks_.find(id);
    return it == landmarks_.end() ? nullptr : &it->second;
}

const Landmark* Map::landmark(LandmarkId id) const {
    auto it = landmarks_.find(id);
    return it == landmarks_.end() ? nullptr : &it->second;
}

std::vector<KeyframeId> Map::lastKeyframes(std::size_t n) const {
    std::vector<KeyframeId> out;
    for (auto it = keyframes_.rbegin(); it != keyframes_.rend() && out.size() < n; ++it)
        out.push_back(it->first);
    std::reverse(out.begin(), out.end());
    return out;
}

std::vector<LandmarkId> Map::landmarksOf(const std::vector<KeyframeId>& kfs) const {
    std::vector<LandmarkId> out;
    std::unordered_set<LandmarkId> seen;
    for (KeyframeId k : kfs)
        for (LandmarkId l : keyframe(k).landmark_of_kp)
            if (l != kNoId && seen.insert(l).second) out.push_back(l);
    return out;
}

std::size_t Map::approxBytes() const {
    std::size_t b = 0;
    for (const auto& [id, kf] : keyframes_) {
        const auto& f = kf.features;
        b += sizeof(Keyframe) + f.keypoints.size() * sizeof(cv::KeyPoint) +
             f.descriptors.total() * f.descriptors.elemSize() + f.depth.size() * sizeof(float) +
             f.points_c.size() * sizeof(Eigen::Vector3d) + f.colors.size() * sizeof(cv::Vec3b) +
             kf.landmark_of_kp.size() * sizeof(LandmarkId);
    }
    for (const auto& [id, lm] : landmarks_)
        b += sizeof(Landmark) + 32 + lm.observations.size() * sizeof(std::pair<KeyframeId, int>);
    return b;
}

}  // namespace devslam::slam
