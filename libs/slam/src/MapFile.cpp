#include <devslam/core/Results.h>
#include <devslam/slam/MapFile.h>

#include <opencv2/core/persistence.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace devslam::slam {

namespace {
constexpr const char* kFormat = "devslam-map";
constexpr int kVersion = 1;

int asInt(std::int64_t v, const char* what) {
    if (v < 0 || v > std::numeric_limits<int>::max())
        throw std::runtime_error(std::string("saveMap: ") + what + " " + std::to_string(v) +
                                 " does not fit the file's 32-bit ids");
    return static_cast<int>(v);
}

/// `fs << key << v`, but an empty list as an empty sequence: OpenCV 4.6's base64 writer
/// asserts on an empty array.
template <typename T>
void put(cv::FileStorage& fs, const char* key, const T& v) {
    fs << key;
    if (v.empty())
        fs << "["
           << "]";
    else
        fs << v;
}

cv::Mat poseMat(const Eigen::Isometry3d& T) {
    cv::Mat m(3, 4, CV_64F);
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) m.at<double>(r, c) = T.matrix()(r, c);
    return m;
}

/// Reading: every error names the file and, through `where`, the element.
struct Reader {
    std::string path;

    [[noreturn]] void fail(const std::string& where, const std::string& what) const {
        throw std::runtime_error(path + ": " + (where.empty() ? "" : where + ": ") + what);
    }
    cv::FileNode need(const cv::FileNode& parent, const char* key, const std::string& where) const {
        cv::FileNode n = parent[key];
        if (n.empty() && !n.isSeq() && !n.isMap() && n.type() == cv::FileNode::NONE)
            fail(where, std::string("no '") + key + "'");
        return n;
    }
    template <typename T>
    T read(const cv::FileNode& parent, const char* key, const std::string& where) const {
        const cv::FileNode n = need(parent, key, where);
        T v{};
        n >> v;
        return v;
    }
    double readFinite(const cv::FileNode& parent, const char* key, const std::string& where) const {
        const cv::FileNode n = need(parent, key, where);
        if (!n.isReal() && !n.isInt()) fail(where, std::string("'") + key + "' is not a number");
        const double v = n.real();
        if (!std::isfinite(v)) fail(where, std::string("'") + key + "' is not finite");
        return v;
    }
    int readInt(const cv::FileNode& parent, const char* key, const std::string& where) const {
        const cv::FileNode n = need(parent, key, where);
        if (!n.isInt()) fail(where, std::string("'") + key + "' is not an integer");
        return static_cast<int>(n);
    }
    template <typename T>
    std::vector<T> readVec(const cv::FileNode& parent, const char* key,
                           const std::string& where) const {
        const cv::FileNode n = need(parent, key, where);
        if (!n.isSeq()) fail(where, std::string("'") + key + "' is not a list");
        std::vector<T> v;
        n >> v;
        return v;
    }
    cv::Mat readMat(const cv::FileNode& parent, const char* key, const std::string& where, int type,
                    int cols) const {
        const cv::FileNode n = need(parent, key, where);
        cv::Mat m;
        if (n.isSeq() && n.size() == 0) return cv::Mat(0, cols, type);  // put's empty list
        n >> m;
        // An empty matrix is written with no data: zero rows of the right kind.
        if (m.empty()) return cv::Mat(0, cols, type);
        if (m.type() != type || m.cols != cols)
            fail(where, std::string("'") + key + "' is not a " + std::to_string(cols) +
                            "-column matrix of the expected type");
        return m;
    }
    Eigen::Isometry3d readPose(const cv::FileNode& parent, const char* key,
                               const std::string& where) const {
        const cv::Mat m = readMat(parent, key, where, CV_64F, 4);
        if (m.rows != 3) fail(where, std::string("'") + key + "' is not a 3x4 matrix");
        Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) {
                const double v = m.at<double>(r, c);
                if (!std::isfinite(v)) fail(where, std::string("'") + key + "' is not finite");
                T.matrix()(r, c) = v;
            }
        const Eigen::Matrix3d R = T.linear();
        if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 ||
            R.determinant() < 0)
            fail(where, std::string("'") + key + "' is not a rotation and translation");
        return T;
    }
};

/// OpenCV's words for a file it could not parse: a parse error carries the file and line in
/// `func` ("map.yml(45): Unexpected end of line"), other errors their condition in `err`.
std::string describe(const cv::Exception& e) {
    const auto close = e.func.find("): ");
    const auto open = e.func.rfind('(', close);
    if (e.code == cv::Error::StsParseError && close != std::string::npos &&
        open != std::string::npos)
        return "line " + e.func.substr(open + 1, close - open - 1) + ": " +
               e.func.substr(close + 3);
    return e.err.empty() ? e.msg : e.err;
}

template <typename T>
void requireSize(const Reader& rd, const std::vector<T>& v, std::size_t n, bool may_be_empty,
                 const char* key, const std::string& where) {
    if (v.size() == n || (may_be_empty && v.empty())) return;
    rd.fail(where, std::string("'") + key + "' has " + std::to_string(v.size()) + " entries for " +
                       std::to_string(n) + " keypoints");
}
}  // namespace

void saveMap(const std::string& path, const Map& map, const OrbExtractor::Options& orb) {
    cv::FileStorage fs(".yml",
                       cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::BASE64);
    fs << "format" << kFormat << "version" << kVersion;
    fs << "orb_scale_factor" << orb.scale_factor << "orb_n_levels" << orb.n_levels;
    fs << "keyframes"
       << "[";
    for (const auto& [id, kf] : map.keyframes()) {
        const FrameFeatures& f = kf.features;
        fs << "{";
        fs << "id" << asInt(id, "keyframe id");
        fs << "frame_index" << asInt(static_cast<std::int64_t>(kf.frame_index), "frame index");
        fs << "timestamp" << kf.timestamp << "T_wc" << poseMat(kf.T_wc);
        put(fs, "keypoints", f.keypoints);
        put(fs, "descriptors", f.descriptors);
        put(fs, "depth", f.depth);
        std::vector<cv::Vec3d> pc(f.points_c.size());
        for (std::size_t i = 0; i < pc.size(); ++i)
            pc[i] = {f.points_c[i].x(), f.points_c[i].y(), f.points_c[i].z()};
        put(fs, "points_c", pc);
        put(fs, "colors", f.colors);
        put(fs, "image_pt", f.image_pt);
        put(fs, "weight", f.weight);
        fs << "gate_exponent" << f.gate_exponent;
        fs << "n_masked" << f.n_masked << "masked_fraction" << f.masked_fraction;
        fs << "}";
    }
    fs << "]";
    // The landmarks column by column (a node per landmark made the file 3x slower to read).
    std::vector<LandmarkId> ids;
    ids.reserve(map.landmarks().size());
    for (const auto& [id, lm] : map.landmarks()) ids.push_back(id);
    std::sort(ids.begin(), ids.end());
    const int n = static_cast<int>(ids.size());
    cv::Mat p_w(n, 3, CV_64F), desc(n, 32, CV_8U), color(n, 3, CV_8U);
    std::vector<int> lid, ref_kf, created_kf, n_visible, n_found, n_obs, obs;
    for (int i = 0; i < n; ++i) {
        const Landmark& lm = *map.landmark(ids[static_cast<std::size_t>(i)]);
        for (int c = 0; c < 3; ++c) {
            p_w.at<double>(i, c) = lm.p_w[c];
            color.at<unsigned char>(i, c) = lm.color[c];
        }
        lm.descriptor.reshape(1, 1).copyTo(desc.row(i));
        lid.push_back(asInt(lm.id, "landmark id"));
        // A landmark's creator may have been culled since: -1, as for none.
        ref_kf.push_back(lm.ref_kf == kNoId ? -1 : asInt(lm.ref_kf, "keyframe id"));
        created_kf.push_back(lm.created_kf == kNoId ? -1 : asInt(lm.created_kf, "keyframe id"));
        n_visible.push_back(lm.n_visible);
        n_found.push_back(lm.n_found);
        n_obs.push_back(static_cast<int>(lm.observations.size()));
        for (const auto& [k, kp] : lm.observations) {
            obs.push_back(asInt(k, "keyframe id"));
            obs.push_back(kp);
        }
    }
    fs << "landmarks"
       << "{";
    fs << "count" << n;
    put(fs, "id", lid);
    put(fs, "p_w", p_w);
    put(fs, "descriptors", desc);
    put(fs, "colors", color);
    put(fs, "ref_kf", ref_kf);
    put(fs, "created_kf", created_kf);
    put(fs, "n_visible", n_visible);
    put(fs, "n_found", n_found);
    put(fs, "n_observations", n_obs);
    put(fs, "observations", obs);
    fs << "}";
    // Last, so that a file cut short (which YAML may still parse) is told as one.
    fs << "end_of_map" << 1;
    core::writeFileWhole(path, fs.releaseAndGetString());
}

MapFile loadMap(const std::string& path) {
    const Reader rd{path};
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        rd.fail("", std::filesystem::exists(path, ec) ? "not a file" : "no such file");
    cv::FileStorage fs;
    try {
        if (!fs.open(path, cv::FileStorage::READ)) rd.fail("", "cannot be read");
    } catch (const cv::Exception& e) {
        // A file cut short or not YAML/JSON/XML: OpenCV's parser names the line.
        rd.fail("", "not a DEV-SLAM map, or cut short (OpenCV: " + describe(e) + ")");
    }
    try {
        const cv::FileNode root = fs.root();
        if (!root.isMap() || root["format"].empty() ||
            static_cast<std::string>(root["format"]) != kFormat)
            rd.fail("", std::string("not a DEV-SLAM map (no 'format: ") + kFormat + "')");
        const int version = rd.readInt(root, "version", "");
        if (version != kVersion)
            rd.fail("", "format version " + std::to_string(version) + ", this build reads " +
                            std::to_string(kVersion));
        if (root["end_of_map"].empty()) rd.fail("", "cut short (no 'end_of_map' at its end)");
        MapFile out;
        out.orb_scale_factor = rd.readFinite(root, "orb_scale_factor", "");
        out.orb_n_levels = rd.readInt(root, "orb_n_levels", "");
        if (out.orb_scale_factor <= 1 || out.orb_n_levels < 1)
            rd.fail("", "orb_scale_factor must be > 1 and orb_n_levels >= 1");

        // Keyframes, renumbered in the saved order.
        const cv::FileNode kfs = rd.need(root, "keyframes", "");
        if (!kfs.isSeq()) rd.fail("", "'keyframes' is not a list");
        std::map<int, KeyframeId> kf_new;  // saved id -> id in the loaded map
        int k_index = 0;
        for (const cv::FileNode& kn : kfs) {
            const std::string where = "keyframe " + std::to_string(k_index++);
            if (!kn.isMap()) rd.fail(where, "not a map of fields");
            Keyframe kf;
            const int saved_id = rd.readInt(kn, "id", where);
            const int frame_index = rd.readInt(kn, "frame_index", where);
            if (frame_index < 0) rd.fail(where, "negative frame_index");
            kf.frame_index = static_cast<std::size_t>(frame_index);
            kf.timestamp = rd.readFinite(kn, "timestamp", where);
            kf.T_wc = rd.readPose(kn, "T_wc", where);
            FrameFeatures& f = kf.features;
            f.keypoints = rd.readVec<cv::KeyPoint>(kn, "keypoints", where);
            const std::size_t n = f.keypoints.size();
            for (const auto& kp : f.keypoints)
                if (!std::isfinite(kp.pt.x) || !std::isfinite(kp.pt.y) || kp.octave < 0 ||
                    kp.octave >= out.orb_n_levels)
                    rd.fail(where, "a keypoint off the image plane or outside the pyramid");
            f.descriptors = rd.readMat(kn, "descriptors", where, CV_8U, 32);
            if (static_cast<std::size_t>(f.descriptors.rows) != n)
                rd.fail(where, "'descriptors' has " + std::to_string(f.descriptors.rows) +
                                   " rows for " + std::to_string(n) + " keypoints");
            f.depth = rd.readVec<float>(kn, "depth", where);
            requireSize(rd, f.depth, n, false, "depth", where);
            const auto pc = rd.readVec<cv::Vec3d>(kn, "points_c", where);
            requireSize(rd, pc, n, false, "points_c", where);
            f.points_c.resize(n);
            for (std::size_t i = 0; i < n; ++i) {
                f.points_c[i] = {pc[i][0], pc[i][1], pc[i][2]};
                if (!std::isfinite(f.depth[i]) || !f.points_c[i].allFinite())
                    rd.fail(where, "a depth or point that is not finite");
            }
            f.colors = rd.readVec<cv::Vec3b>(kn, "colors", where);
            requireSize(rd, f.colors, n, false, "colors", where);
            f.image_pt = rd.readVec<cv::Point2f>(kn, "image_pt", where);
            requireSize(rd, f.image_pt, n, true, "image_pt", where);
            f.weight = rd.readVec<float>(kn, "weight", where);
            requireSize(rd, f.weight, n, true, "weight", where);
            f.gate_exponent = rd.readFinite(kn, "gate_exponent", where);
            f.n_masked = rd.readInt(kn, "n_masked", where);
            f.masked_fraction = rd.readFinite(kn, "masked_fraction", where);
            if (kf_new.count(saved_id)) rd.fail(where, "id " + std::to_string(saved_id) + " twice");
            kf_new[saved_id] = out.map.addKeyframe(std::move(kf));
        }

        // Landmarks.
        const cv::FileNode ln = rd.need(root, "landmarks", "");
        if (!ln.isMap()) rd.fail("", "'landmarks' is not a map of fields");
        const std::string lw = "landmarks";
        const int count = rd.readInt(ln, "count", lw);
        if (count < 0) rd.fail(lw, "negative count");
        const auto n = static_cast<std::size_t>(count);
        const cv::Mat p_w = rd.readMat(ln, "p_w", lw, CV_64F, 3);
        const cv::Mat desc = rd.readMat(ln, "descriptors", lw, CV_8U, 32);
        const cv::Mat color = rd.readMat(ln, "colors", lw, CV_8U, 3);
        if (static_cast<std::size_t>(p_w.rows) != n || static_cast<std::size_t>(desc.rows) != n ||
            static_cast<std::size_t>(color.rows) != n)
            rd.fail(lw, "p_w, descriptors and colors must have 'count' rows");
        const auto ids = rd.readVec<int>(ln, "id", lw);
        const auto ref_kf = rd.readVec<int>(ln, "ref_kf", lw);
        const auto created_kf = rd.readVec<int>(ln, "created_kf", lw);
        const auto n_visible = rd.readVec<int>(ln, "n_visible", lw);
        const auto n_found = rd.readVec<int>(ln, "n_found", lw);
        const auto n_obs = rd.readVec<int>(ln, "n_observations", lw);
        const auto obs = rd.readVec<int>(ln, "observations", lw);
        for (const auto* v : {&ids, &ref_kf, &created_kf, &n_visible, &n_found, &n_obs})
            if (v->size() != n) rd.fail(lw, "every column must have 'count' entries");
        std::set<std::pair<KeyframeId, int>> seen;
        std::size_t o = 0;
        const auto kfOf = [&](int saved, const std::string& where) -> KeyframeId {
            const auto it = kf_new.find(saved);
            if (it == kf_new.end())
                rd.fail(where, "keyframe id " + std::to_string(saved) + " is not in the map");
            return it->second;
        };
        for (std::size_t i = 0; i < n; ++i) {
            const std::string where =
                "landmark " + std::to_string(i) + " (id " + std::to_string(ids[i]) + ")";
            const int r = static_cast<int>(i);
            const Eigen::Vector3d p(p_w.at<double>(r, 0), p_w.at<double>(r, 1),
                                    p_w.at<double>(r, 2));
            if (!p.allFinite()) rd.fail(where, "a position that is not finite");
            if (n_obs[i] < 1) rd.fail(where, "no observation");
            if (obs.size() < o + 2 * static_cast<std::size_t>(n_obs[i]))
                rd.fail(where, "'observations' ends before its observations");
            LandmarkId lm = kNoId;
            for (int j = 0; j < n_obs[i]; ++j, o += 2) {
                const KeyframeId k = kfOf(obs[o], where);
                const int kp = obs[o + 1];
                if (kp < 0 || kp >= static_cast<int>(out.map.keyframe(k).features.size()))
                    rd.fail(where, "keyframe id " + std::to_string(obs[o]) + " has no keypoint " +
                                       std::to_string(kp));
                if (!seen.emplace(k, kp).second)
                    rd.fail(where, "keypoint " + std::to_string(kp) + " of keyframe id " +
                                       std::to_string(obs[o]) + " observes two landmarks");
                if (lm == kNoId) {
                    const cv::Vec3b c(color.at<unsigned char>(r, 0), color.at<unsigned char>(r, 1),
                                      color.at<unsigned char>(r, 2));
                    lm = out.map.addLandmark(p, desc.row(r), c, k, kp);
                } else {
                    out.map.addObservation(lm, k, kp);
                }
            }
            Landmark& l = *out.map.landmark(lm);
            // The anchor must be in the map; the creator may have been culled before saving.
            l.ref_kf = kfOf(ref_kf[i], where);
            const auto created = kf_new.find(created_kf[i]);
            l.created_kf = created == kf_new.end() ? kNoId : created->second;
            l.n_visible = n_visible[i];
            l.n_found = n_found[i];
        }
        if (o != obs.size())
            rd.fail(lw, "'observations' has " + std::to_string(obs.size() - o) +
                            " entries past the last landmark's");
        return out;
    } catch (const cv::Exception& e) {
        rd.fail("", "not a DEV-SLAM map, or cut short (OpenCV: " + describe(e) + ")");
    }
}

void checkOrbMatches(const MapFile& m, const std::string& path, const OrbExtractor::Options& orb) {
    if (std::abs(m.orb_scale_factor - orb.scale_factor) > 1e-9 || m.orb_n_levels != orb.n_levels)
        throw std::invalid_argument(
            path + ": the map's keypoints come from an ORB pyramid of scale_factor " +
            std::to_string(m.orb_scale_factor) + ", n_levels " + std::to_string(m.orb_n_levels) +
            "; this run's [orb] has " + std::to_string(orb.scale_factor) + ", " +
            std::to_string(orb.n_levels) + " (localize with the INI the map was made with)");
}

}  // namespace devslam::slam
