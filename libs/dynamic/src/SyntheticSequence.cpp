#include <devslam/dynamic/SyntheticSequence.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <random>
#include <stdexcept>

namespace devslam::dynamic {

namespace {
constexpr double kDeg = M_PI / 180.0;

/// A textured rectangle (or infinite plane when `bounded` is false) in the world.
struct Plane {
    Eigen::Vector3d origin;  ///< [m] texture centre
    Eigen::Vector3d ex, ey;  ///< unit in-plane axes (texture u, v directions)
    double px_per_m;         ///< texture pixels per metre
    double half_w, half_h;   ///< [m] extent when bounded
    bool bounded;
    [[nodiscard]] Eigen::Vector3d normal() const { return ex.cross(ey); }
};
}  // namespace

std::vector<SyntheticFrame> makeSyntheticSequence(const SyntheticOptions& o,
                                                  const cv::Mat& wall_bgr,
                                                  const cv::Mat& person_bgr) {
    if (wall_bgr.type() != CV_8UC3 || person_bgr.type() != CV_8UC3)
        throw std::invalid_argument("synthetic sequence: textures must be CV_8UC3");
    if (o.n_frames < 1 || o.n_frames > kMaxSyntheticFrames || o.fps <= 0)
        throw std::invalid_argument("synthetic sequence: n_frames 1.." +
                                    std::to_string(kMaxSyntheticFrames) + " and fps > 0 needed");
    core::CameraIntrinsics K;  // 640x480, fx = fy = 525 (fr1-like)
    const double dt = 1.0 / o.fps;
    std::mt19937 rng(o.seed);
    std::normal_distribution<double> gauss(0.0, 1.0);

    Plane wall;
    const double tilt = o.wall_tilt_deg * kDeg;
    wall.origin = {0, 0, o.wall_depth};
    wall.ex = {std::cos(tilt), 0, std::sin(tilt)};
    wall.ey = {0, 1, 0};
    wall.px_per_m = wall_bgr.cols / 6.0;  // the photo spans 6 m of wall, then repeats mirrored
    wall.half_w = wall.half_h = 0;
    wall.bounded = false;

    Plane person;
    person.ex = {1, 0, 0};
    person.ey = {0, 1, 0};
    person.px_per_m = person_bgr.rows / o.person_height;
    person.half_h = o.person_height / 2;
    person.half_w = person_bgr.cols / person.px_per_m / 2;
    person.bounded = true;

    std::vector<SyntheticFrame> seq;
    Eigen::Isometry3d T_prev = Eigen::Isometry3d::Identity();
    cv::Mat map_wx(K.height, K.width, CV_32FC1), map_wy(K.height, K.width, CV_32FC1);
    // Set only where the person is seen; elsewhere remap reads them too (its result there is
    // not used), so they hold a defined value rather than uninitialised memory.
    cv::Mat map_px(K.height, K.width, CV_32FC1, cv::Scalar(-1)),
        map_py(K.height, K.width, CV_32FC1, cv::Scalar(-1));
    for (int k = 0; k < o.n_frames; ++k) {
        const double t = k * dt;
        Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();
        const Eigen::Vector3d ang = o.cam_rate_deg * kDeg * t;
        T_wc.linear() = (Eigen::AngleAxisd(ang.y(), Eigen::Vector3d::UnitY()) *
                         Eigen::AngleAxisd(ang.x(), Eigen::Vector3d::UnitX()) *
                         Eigen::AngleAxisd(ang.z(), Eigen::Vector3d::UnitZ()))
                            .toRotationMatrix();
        T_wc.translation() = o.cam_velocity * t;
        const bool has_person = o.person != PersonMotion::None;
        const double walked = o.person == PersonMotion::Walking ? o.person_speed * t : 0.0;
        const Eigen::Vector3d dir = o.person_direction.normalized();
        person.origin = {o.person_x0 + walked * dir.x(), 0.1, o.person_depth + walked * dir.z()};

        cv::Mat depth(K.height, K.width, CV_32FC1, cv::Scalar(0.f));
        cv::Mat person_hit(K.height, K.width, CV_8UC1, cv::Scalar(0));
        const Eigen::Matrix3d R = T_wc.linear();
        const Eigen::Vector3d c = T_wc.translation();
        float umin = 1e9f, vmin = 1e9f, umax = -1e9f, vmax = -1e9f;
        for (int v = 0; v < K.height; ++v) {
            for (int u = 0; u < K.width; ++u) {
                const Eigen::Vector3d d =
                    R * Eigen::Vector3d((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1);
                // Ray o + s * d hits a plane at s = n.(p0 - o) / n.d; s is the camera depth.
                auto hit = [&](const Plane& p, double& s, double& tu, double& tv) {
                    const Eigen::Vector3d n = p.normal();
                    const double nd = n.dot(d);
                    if (std::abs(nd) < 1e-9) return false;
                    s = n.dot(p.origin - c) / nd;
                    if (s <= 0) return false;
                    const Eigen::Vector3d q = c + s * d - p.origin;
                    const double a = q.dot(p.ex), b = q.dot(p.ey);
                    if (p.bounded && (std::abs(a) > p.half_w || std::abs(b) > p.half_h))
                        return false;
                    tu = a * p.px_per_m;
                    tv = b * p.px_per_m;
                    return true;
                };
                double s_w = 0, wu = 0, wv = 0, s_p = 0, pu = 0, pv = 0;
                const bool hw = hit(wall, s_w, wu, wv);
                const bool hp = has_person && hit(person, s_p, pu, pv) && (!hw || s_p < s_w);
                if (hp) {
                    person_hit.at<uchar>(v, u) = 255;
                    depth.at<float>(v, u) = static_cast<float>(s_p);
                    map_px.at<float>(v, u) = static_cast<float>(pu + person_bgr.cols / 2.0);
                    map_py.at<float>(v, u) = static_cast<float>(pv + person_bgr.rows / 2.0);
                    umin = std::min(umin, static_cast<float>(u));
                    umax = std::max(umax, static_cast<float>(u));
                    vmin = std::min(vmin, static_cast<float>(v));
                    vmax = std::max(vmax, static_cast<float>(v));
                } else if (hw) {
                    depth.at<float>(v, u) = static_cast<float>(s_w);
                }
                map_wx.at<float>(v, u) = static_cast<float>(wu + wall_bgr.cols / 2.0);
                map_wy.at<float>(v, u) = static_cast<float>(wv + wall_bgr.rows / 2.0);
            }
        }
        cv::Mat img, person_img;
        cv::remap(wall_bgr, img, map_wx, map_wy, cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
        if (has_person) {
            cv::remap(person_bgr, person_img, map_px, map_py, cv::INTER_LINEAR,
                      cv::BORDER_REPLICATE);
            person_img.copyTo(img, person_hit);
        }
        cv::Mat noise(img.size(), CV_32FC1), noise3, imgf;
        cv::RNG cv_rng(rng());  // seeded from the sequence's own generator
        cv_rng.fill(noise, cv::RNG::NORMAL, 0.0, o.image_noise);
        cv::merge(std::vector<cv::Mat>{noise, noise, noise}, noise3);
        img.convertTo(imgf, CV_32FC3);
        imgf += noise3;
        imgf.convertTo(img, CV_8UC3);
        for (int v = 0; v < depth.rows; ++v)
            for (int u = 0; u < depth.cols; ++u) {
                float& z = depth.at<float>(v, u);
                if (z > 0) z = static_cast<float>(z + o.depth_noise * z * z * gauss(rng));
            }

        SyntheticFrame f;
        f.frame.index = static_cast<std::size_t>(k);
        f.frame.timestamp = t;
        f.frame.bgr = img;
        f.frame.depth = depth;
        f.frame.K = K;
        f.frame.rgb_source = "synthetic";
        f.T_w_c = T_wc;
        f.T_prev_cur =
            k == 0 ? Eigen::Isometry3d::Identity() : Eigen::Isometry3d(T_prev.inverse() * T_wc);
        if (umax >= umin && (umax - umin) * (vmax - vmin) > 400.f)
            f.person_box = cv::Rect2f(umin, vmin, umax - umin + 1, vmax - vmin + 1);
        T_prev = T_wc;
        seq.push_back(std::move(f));
    }
    return seq;
}

}  // namespace devslam::dynamic
