#include <devslam/io/Rawlog.h>

#include "TextFile.h"

#include <devslam/core/Camera.h>
#include <devslam/core/GzFile.h>
#include <devslam/core/Pose.h>

#include <mrpt/core/aligned_allocator.h>
#include <mrpt/img/CImage.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/filesystem.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <future>
#include <limits>
#include <new>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>

#include <zlib.h>

namespace fs = std::filesystem;
using mrpt::obs::CObservation3DRangeScan;

namespace devslam::io {

std::string rawlogImagesDir(const std::string& rawlog_path) {
    const fs::path p(rawlog_path);
    const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
    return (dir / (p.stem().string() + "_Images")).string();
}

namespace {

// The largest block operator new gives on this thread (SIZE_MAX: no cap), set while an
// object is decoded: see the operator new at the end of this file.
thread_local std::size_t t_new_block_cap = std::numeric_limits<std::size_t>::max();

/// While alive, a single operator-new block over `bytes` on this thread throws
/// std::bad_alloc instead of being allocated.
class NewBlockCap {
  public:
    explicit NewBlockCap(std::size_t bytes) : before_(t_new_block_cap) {
        t_new_block_cap = bytes;
    }
    ~NewBlockCap() { t_new_block_cap = before_; }
    NewBlockCap(const NewBlockCap&) = delete;
    NewBlockCap& operator=(const NewBlockCap&) = delete;

  private:
    std::size_t before_;
};

// Optical frame of MRPT's 3D-scan depth camera, seen from the observation frame (X forward,
// Y left, Z up): the (0,0,0,-90deg,0,-90deg) rotation of CObservation3DRangeScan.
const mrpt::poses::CPose3D& opticalInObs() {
    static const mrpt::poses::CPose3D kPose(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
    return kPose;
}

double roundedScale(float range_units) {
    const double s = 1.0 / static_cast<double>(range_units);
    return std::abs(s - std::round(s)) < 1e-3 * s ? std::round(s) : s;
}

// Depth image in metres in the depth camera (range_is_depth handled).
// Each pixel of camera `K` (K.width x K.height, row-major) with its lens distortion removed:
// the pixel the pinhole backprojection is exact for. Computed once per camera (the frames of
// a rawlog share one).
const std::vector<cv::Point2f>& undistortedGrid(const core::CameraIntrinsics& K) {
    thread_local core::CameraIntrinsics cached;
    thread_local std::vector<cv::Point2f> grid;
    if (!grid.empty() && cached == K) return grid;
    std::vector<cv::Point2f> px;
    px.reserve(static_cast<std::size_t>(K.width) * static_cast<std::size_t>(K.height));
    for (int v = 0; v < K.height; ++v)
        for (int u = 0; u < K.width; ++u)
            px.emplace_back(static_cast<float>(u), static_cast<float>(v));
    grid = core::undistortPixels(px, K);
    cached = K;
    return grid;
}

core::CameraIntrinsics depthCamera(const CObservation3DRangeScan& o) {
    auto K = core::CameraIntrinsics::fromMrpt(o.cameraParams);
    K.width = static_cast<int>(o.rangeImage.cols());
    K.height = static_cast<int>(o.rangeImage.rows());
    return K;
}

// The depth image in metres along the depth camera's axis; `K` is depthCamera(o).
cv::Mat depthInDepthCamera(const CObservation3DRangeScan& o, const core::CameraIntrinsics& K) {
    const int H = static_cast<int>(o.rangeImage.rows()), W = static_cast<int>(o.rangeImage.cols());
    const cv::Mat raw(H, W, CV_16UC1, const_cast<uint16_t*>(o.rangeImage.data()));
    cv::Mat m;
    raw.convertTo(m, CV_32F, o.rangeUnits);
    if (!o.range_is_depth) {  // Euclidean range along the pixel's ray -> z
        const auto& ray = undistortedGrid(K);
        for (int v = 0; v < H; ++v)
            for (int u = 0; u < W; ++u) {
                const auto& q = ray[static_cast<std::size_t>(v) * W + u];
                const double x = (q.x - K.cx) / K.fx, y = (q.y - K.cy) / K.fy;
                m.at<float>(v, u) /= static_cast<float>(std::sqrt(1 + x * x + y * y));
            }
    }
    return m;
}

// Reprojects depth from the depth camera into the colour camera (z-buffered, nearest pixel),
// through both lenses: a depth pixel is undistorted before it is backprojected, and its point
// lands on the colour image where the colour lens puts it (the raw, distorted pixel, where
// the SLAM looks depth up). With pinhole models only, an OpenNI colour lens (k1 0.06, k2 0.04)
// put depth up to ~20 px from its colour near the image corners.
cv::Mat registerDepth(const CObservation3DRangeScan& o, const cv::Mat& depth,
                      const core::CameraIntrinsics& Kd, const core::CameraIntrinsics& Kc) {
    const auto& ray = undistortedGrid(Kd);
    // colour optical <- depth optical
    const mrpt::poses::CPose3D T = (o.relativePoseIntensityWRTDepth - opticalInObs());
    const Eigen::Isometry3d Tci = core::toIsometry(T).inverse();
    const int W = Kc.width, H = Kc.height;
    // The colour image's extent in normalized coordinates (its border undistorted), with a
    // margin: the distortion polynomial folds points far outside the view back into it.
    float x0 = 0, x1 = 0, y0 = 0, y1 = 0;
    if (Kc.distorted()) {
        std::vector<cv::Point2f> border;
        for (int k = 0; k <= 32; ++k) {
            const float u = static_cast<float>(k * (W - 1)) / 32,
                        v = static_cast<float>(k * (H - 1)) / 32;
            border.insert(
                border.end(),
                {{u, 0}, {u, static_cast<float>(H - 1)}, {0, v}, {static_cast<float>(W - 1), v}});
        }
        x0 = y0 = std::numeric_limits<float>::max();
        x1 = y1 = std::numeric_limits<float>::lowest();
        for (const auto& b : core::undistortPixels(border, Kc)) {
            const float x = static_cast<float>((b.x - Kc.cx) / Kc.fx);
            const float y = static_cast<float>((b.y - Kc.cy) / Kc.fy);
            x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
        }
        const float mx = 0.05f * (x1 - x0), my = 0.05f * (y1 - y0);
        x0 -= mx, x1 += mx, y0 -= my, y1 += my;
    }
    std::vector<cv::Point3f> pts;  // in the colour camera's optical frame
    pts.reserve(static_cast<std::size_t>(cv::countNonZero(depth > 0)));
    for (int v = 0; v < depth.rows; ++v)
        for (int u = 0; u < depth.cols; ++u) {
            const float z = depth.at<float>(v, u);
            if (!(z > 0)) continue;
            const auto& r = ray[static_cast<std::size_t>(v) * depth.cols + u];
            const Eigen::Vector3d q = Tci * core::backproject(r.x, r.y, z, Kd);
            if (q.z() <= 0) continue;
            if (Kc.distorted()) {
                const double x = q.x() / q.z(), y = q.y() / q.z();
                if (x < x0 || x > x1 || y < y0 || y > y1) continue;
            }
            pts.emplace_back(static_cast<float>(q.x()), static_cast<float>(q.y()),
                             static_cast<float>(q.z()));
        }
    std::vector<cv::Point2f> px;
    if (Kc.distorted() && !pts.empty()) {
        const cv::Mat D(1, 5, CV_64F, const_cast<double*>(Kc.dist.data()));
        cv::projectPoints(pts, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), Kc.cvMatrix(), D, px);
    } else {
        px.reserve(pts.size());
        for (const auto& q : pts)
            px.emplace_back(static_cast<float>(Kc.fx * q.x / q.z + Kc.cx),
                            static_cast<float>(Kc.fy * q.y / q.z + Kc.cy));
    }
    cv::Mat out(H, W, CV_32F, cv::Scalar(0));
    for (std::size_t i = 0; i < pts.size(); ++i) {
        const long ui = std::lround(px[i].x), vi = std::lround(px[i].y);
        if (ui < 0 || vi < 0 || ui >= W || vi >= H) continue;
        auto& d = out.at<float>(static_cast<int>(vi), static_cast<int>(ui));
        if (d == 0 || pts[i].z < d) d = pts[i].z;
    }
    return out;
}

// The first externally stored file of `o` that is not there ("" when none is missing).
// MRPT opens them only when a frame is read; checking at open makes a missing one damage
// found up front, as a TUM folder's missing image is.
std::string missingExternalFile(const CObservation3DRangeScan& o) {
    if (o.hasIntensityImage && o.intensityImage.isExternallyStored()) {
        const std::string p = o.intensityImage.getExternalStorageFileAbsolutePath();
        if (!fs::is_regular_file(p)) return p;
    }
    if (o.hasRangeImage && o.rangeImage_isExternallyStored()) {
        const std::string p = o.rangeImage_getExternalStorageFileAbsolutePath("");
        if (!fs::is_regular_file(p)) return p;
    }
    return "";
}

// MRPT's message for an unknown class quotes the name as read: in a damaged or foreign file,
// garbage bytes sent to the terminal. Only printable ASCII is kept ('?' for others), and a
// quoted class name is cut to 60 characters.
std::string printable(std::string m) {
    for (char& c : m)
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
    const std::string open = "class '";
    if (const auto a = m.find(open); a != std::string::npos) {
        const auto from = a + open.size(), to = m.find("' which", from);
        if (to != std::string::npos && to - from > 60) m.replace(from + 57, to - from - 57, "...");
    }
    return m;
}

}  // namespace

core::Frame frameFromObservation(const CObservation3DRangeScan& o, const std::string& what) {
    cv::Mat img;  // an external one is decoded here, when first used
    try {
        if (o.hasIntensityImage && !o.intensityImage.isEmpty()) img = o.intensityImage.asCvMatRef();
    } catch (const std::exception& e) {
        // (MRPT's text was its banner alone for a zero-byte file, naming none)
        const auto& c = o.intensityImage;
        throw std::runtime_error(
            what + ": " +
            (c.isExternallyStored()
                 ? "external colour image '" + c.getExternalStorageFileAbsolutePath() + "'"
                 : std::string("colour image")) +
            " does not decode (" + core::innermostMessage(e.what()) + ")");
    }
    if (img.empty()) throw std::runtime_error(what + ": observation has no colour image");
    if (!o.hasRangeImage || o.rangeImage.rows() == 0)
        throw std::runtime_error(what + ": observation has no depth image");
    core::Frame f;
    f.timestamp = mrpt::Clock::toDouble(o.timestamp);
    if (img.channels() == 3)
        f.bgr = img.clone();  // CImage colour is BGR
    else if (img.channels() == 1)
        cv::cvtColor(img, f.bgr, cv::COLOR_GRAY2BGR);
    else
        throw std::runtime_error(what + ": colour image has " + std::to_string(img.channels()) +
                                 " channels (1 or 3 expected)");
    if (f.bgr.depth() != CV_8U)
        throw std::runtime_error(what + ": colour image must be 8 bits per channel");

    // Values 1..13 with millimetre units are MRPT's rgbd_dataset2rawlog bug (metres truncated
    // into uint16); refuse them instead of producing a wall 1 mm in front of the camera.
    uint16_t max_raw = 0;
    for (std::size_t k = 0; k < static_cast<std::size_t>(o.rangeImage.size()); ++k)
        max_raw = std::max(max_raw, o.rangeImage.data()[k]);
    if (max_raw > 0 && max_raw < 20 && o.rangeUnits >= 0.0005f)
        throw std::runtime_error(
            what + ": depth values are at most " + std::to_string(max_raw) + " units of " +
            std::to_string(o.rangeUnits) +
            " m: metres truncated to integers (MRPT rgbd_dataset2rawlog bug)?");
    // A unit of 1 m, 1e6 m or 1e-9 m (a damaged file) put every depth beyond range or under
    // a millimetre: frames without depth, without a word. As [dataset] tum_depth_scale.
    if (!(o.rangeUnits >= 1e-6f && o.rangeUnits <= 0.1f))
        throw std::runtime_error(what + ": depth unit (rangeUnits) " +
                                 std::to_string(o.rangeUnits) + " m: must be in [1e-6, 0.1] m");
    {  // A NaN or 1e10 m offset between the two cameras registered no depth pixel at all.
        const auto& T = o.relativePoseIntensityWRTDepth;
        const double t = std::sqrt(T.x() * T.x() + T.y() * T.y() + T.z() * T.z());
        if (!std::isfinite(t) || !T.getRotationMatrix().asEigen().allFinite() || t > 1.0)
            throw std::runtime_error(what +
                                     ": the colour camera's pose relative to the depth camera "
                                     "(relativePoseIntensityWRTDepth) is " +
                                     T.asString() + ": must be finite and within 1 m");
    }
    f.depth_scale = roundedScale(o.rangeUnits);
    // Both cameras' models before any pixel is projected with them: a focal length of 0 or
    // inf (a damaged file) made the SLAM's grid map loop forever, with no error on the way.
    for (const auto& [name, cam, w, h] :
         {std::tuple{"colour", &o.cameraParamsIntensity, f.bgr.cols, f.bgr.rows},
          std::tuple{"depth", &o.cameraParams, static_cast<int>(o.rangeImage.cols()),
                     static_cast<int>(o.rangeImage.rows())}}) {
        auto K = core::CameraIntrinsics::fromMrpt(*cam);
        // A calibration made for another resolution has its principal point and focal
        // lengths in the wrong pixels (a 640x480 one on a 320x240 image still passes the
        // checks below, its principal point in the image's corner).
        if (cam->ncols != 0 && cam->nrows != 0 && (K.width != w || K.height != h))
            throw std::runtime_error(what + ": " + name + " camera: its calibration is for " +
                                     std::to_string(K.width) + "x" + std::to_string(K.height) +
                                     " but the image is " + std::to_string(w) + "x" +
                                     std::to_string(h));
        K.width = w;
        K.height = h;
        if (const std::string p = K.problem(); !p.empty())
            throw std::runtime_error(what + ": " + name + " camera: " + p);
    }
    f.K = core::CameraIntrinsics::fromMrpt(o.cameraParamsIntensity);
    f.K.width = f.bgr.cols;
    f.K.height = f.bgr.rows;
    const auto Kd = depthCamera(o);
    const cv::Mat depth = depthInDepthCamera(o, Kd);
    // (registered depth: one camera, the same pixels, lens included)
    const bool same_camera = o.doDepthAndIntensityCamerasCoincide() && Kd == f.K;
    f.depth = same_camera ? depth : registerDepth(o, depth, Kd, f.K);
    f.rgb_source = what;
    f.depth_source = what;
    core::validateFrame(f, what);
    return f;
}

// ---------------------------------------------------------------------------------------
struct RawlogReader::Stream {
    explicit Stream(const std::string& path)
        : path(path), file(path), arch(mrpt::serialization::archiveFrom(file)) {}
    std::string path;
    mrpt::io::CFileGZInputStream file;
    mrpt::serialization::CArchiveStreamBase<mrpt::io::CFileGZInputStream> arch;
    std::vector<CObservation3DRangeScan::Ptr> pending;  // from the current sensory frame
    std::size_t objects = 0;

    /// For a first object that does not decode: what the file starts with (a text file given
    /// as a rawlog got MRPT's "old streaming header" alone).
    std::string notARawlog() const {
        char head[24] = {};
        std::size_t n = 0;
        try {
            mrpt::io::CFileGZInputStream again(path);
            n = again.Read(head, sizeof head);
        } catch (const std::exception&) {
        }
        // MRPT's objects start with 0x80 + the class name's length, then the name: "C..." in
        // old rawlogs, "mrpt::obs::C..." since MRPT 2.
        const std::string name(head + std::min<std::size_t>(n, 1), head + n);
        if (n >= 2 && (static_cast<unsigned char>(head[0]) & 0x80) &&
            (name[0] == 'C' || name.rfind("mrpt::", 0) == 0))
            return "";
        return ": not a rawlog? It starts with '" + printable(std::string(head, n)) +
               "' where a rawlog starts with an MRPT class name (CSensoryFrame, "
               "CObservation3DRangeScan...)";
    }

    // Next 3D scan (optionally of one sensor label); nullptr at a clean end. Counts other
    // observations in `skipped`. Throws on damage.
    CObservation3DRangeScan::Ptr next(const std::string& label, std::size_t& skipped, bool& saw_sf,
                                      bool& saw_obs) {
        for (;;) {
            while (!pending.empty()) {
                auto o = pending.front();
                pending.erase(pending.begin());
                if (label.empty() || o->sensorLabel == label) return o;
                ++skipped;
            }
            mrpt::serialization::CSerializable::Ptr obj;
            const uint64_t pos = file.getPosition();
            try {
                // 256 MiB: a 3D scan's point list of 67 million points (an 8K x 8K depth
                // image), where this project's are 300 000 (operator new, end of this file).
                const NewBlockCap cap(std::size_t(256) << 20);
                obj = arch.ReadObject();
            } catch (const mrpt::serialization::CExceptionEOF&) {
                if (file.getPosition() == pos && file.checkEOF()) return nullptr;  // clean end
                throw std::runtime_error("truncated object at byte " + std::to_string(pos));
            } catch (const std::exception& e) {
                // Cut inside an object's data: MRPT's archive says "Truncated data stream"
                // (no EOF exception); at byte 0 that read as "not a rawlog?".
                // (A file cut inside its first object, at the image's bytes, gets "Cannot read
                // requested number of bytes" instead, which read as "cannot decode".)
                const std::string why = core::innermostMessage(e.what());
                if (why.find("Truncated data stream") != std::string::npos ||
                    why.find("Cannot read requested number of bytes") != std::string::npos)
                    throw std::runtime_error(
                        "truncated object at byte " + std::to_string(pos) +
                        (objects == 0 && pos == 0 ? notARawlog() : "") + " (object " +
                        std::to_string(objects) +
                        " of the uncompressed stream ends early: " + printable(why) + ")");
                throw std::runtime_error("cannot decode object " + std::to_string(objects) +
                                         " at byte " + std::to_string(pos) +
                                         " of the uncompressed stream" +
                                         (objects == 0 && pos == 0 ? notARawlog() : "") + " (" +
                                         printable(core::innermostMessage(e.what())) + ")");
            }
            ++objects;
            if (auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(obj)) {
                saw_sf = true;
                for (const auto& o : *sf) {
                    if (auto o3 = std::dynamic_pointer_cast<CObservation3DRangeScan>(o))
                        pending.push_back(o3);
                    else
                        ++skipped;
                }
            } else if (auto o3 = std::dynamic_pointer_cast<CObservation3DRangeScan>(obj)) {
                saw_obs = true;
                pending.push_back(o3);
            } else if (std::dynamic_pointer_cast<mrpt::obs::CActionCollection>(obj)) {
                saw_sf = true;
            } else {
                if (std::dynamic_pointer_cast<mrpt::obs::CObservation>(obj)) saw_obs = true;
                ++skipped;
            }
        }
    }
};

namespace {
/// "colour camera 640x480 fx 517.3 ... differs from observation 0's ...".
std::string cameraChange(const mrpt::img::TCamera& now, const mrpt::img::TCamera& first) {
    const auto text = [](const mrpt::img::TCamera& c) {
        std::ostringstream s;
        s << c.ncols << "x" << c.nrows << " fx " << c.fx() << " fy " << c.fy() << " cx "
          << c.cx() << " cy " << c.cy();
        return s.str();
    };
    return "colour camera " + text(now) + " differs from observation 0's " + text(first) +
           ": a rawlog of one camera is expected";
}
}  // namespace

RawlogReader::RawlogReader(std::string path, ReaderOptions opts)
    : path_(std::move(path)), opts_(std::move(opts)) {
    if (!fs::is_regular_file(path_)) throw std::runtime_error(path_ + ": rawlog file not found");
    mrpt::img::CImage::setImagesPathBase(rawlogImagesDir(path_));
    // Scan once: count frames, find damage, take the intrinsics of the first frame.
    std::size_t skipped = 0;
    bool saw_sf = false, saw_obs = false;
    // Not damage: a rawlog of two RGB-D sensors read without a label gave both cameras' frames
    // as one camera's (or, synchronised in one sensory frame, a "duplicate timestamp").
    struct MixedSensors : std::runtime_error {
        using std::runtime_error::runtime_error;
    };
    std::string first_label;
    mrpt::img::TCamera first_cam;
    core::CameraIntrinsics first_calibration;  // first_cam's, compared with each observation's
    // zlib's verdict on the whole file (damage inside it, data after its end), found on a
    // second thread beside the scan: reading a 700 MB rawlog through took 5 s on its own, as
    // long as the scan, and was done twice after it. Stopped when the scan fails otherwise.
    core::GzipCheckControl control;
    std::future<core::GzipCheck> check_future =
        std::async(std::launch::async | std::launch::deferred,
                   [this, &control] { return core::gzipCheck(path_, &control); });
    struct StopOnExit {  // (destroyed before the future, whose destructor waits for it)
        std::atomic<bool>& stop;
        ~StopOnExit() { stop = true; }
    } stop_on_exit{control.stop};
    // Progress: in a gzip file the check's place stands for the scan's (MRPT's stream tells no
    // place in the compressed file; both read it through at about the same pace); a plain
    // rawlog, which the check does not read, is as far as the scan.
    const std::uint64_t file_bytes = fs::file_size(path_);
    const bool gzip = [&] {
        unsigned char magic[2] = {};
        std::FILE* f = std::fopen(path_.c_str(), "rb");
        const bool is =
            f != nullptr && std::fread(magic, 1, 2, f) == 2 && magic[0] == 0x1f && magic[1] == 0x8b;
        if (f != nullptr) std::fclose(f);
        return is;
    }();
    const auto progress = [&](std::uint64_t at) {
        if (opts_.on_open && !opts_.on_open(n_frames_, at, file_bytes))
            throw OpeningStopped(path_ + ": opening stopped after " + std::to_string(n_frames_) +
                                 " RGB-D observations of it were found");
    };
    // The check's verdict, waited for; the wait is a part of the opening too, shown and
    // stoppable (a scan that broke early, on a camera change, waits for the whole file).
    std::optional<core::GzipCheck> check;
    const auto checked = [&]() -> const core::GzipCheck& {
        if (check) return *check;
        while (check_future.wait_for(std::chrono::milliseconds(100)) == std::future_status::timeout)
            progress(std::min(file_bytes, control.bytes_read.load()));
        try {
            check = check_future.get();
        } catch (const std::exception& e) {  // (its buffers not had: out of memory)
            check = core::GzipCheck{std::string("zlib's check failed: ") + e.what(), "", false};
        }
        return *check;
    };
    try {
        Stream s(path_);
        double last_t = 0;
        while (auto o = s.next(opts_.sensor_label, skipped, saw_sf, saw_obs)) {
            if (n_frames_ == 0) first_label = o->sensorLabel;
            if (opts_.sensor_label.empty() && o->sensorLabel != first_label)
                throw MixedSensors(path_ + ": RGB-D observations of more than one sensor ('" +
                                   first_label + "' from observation 0, '" + o->sensorLabel +
                                   "' at observation " + std::to_string(n_frames_) +
                                   "): choose one with [dataset] sensor_label");
            if (const std::string m = missingExternalFile(*o); !m.empty())
                throw std::runtime_error("observation " + std::to_string(n_frames_) +
                                         ": external file '" + m + "' not found");
            // As in a TUM list: a stamp not after the previous one is refused (the frames
            // before it are the intact part).
            const double t = mrpt::Clock::toDouble(o->timestamp);
            if (n_frames_ > 0 && !(t > last_t))
                throw std::runtime_error("observation " + std::to_string(n_frames_) + ": " +
                                         detail::stampNotAfter(t, last_t, detail::stampText(t)) +
                                         " (previous observation " + std::to_string(n_frames_ - 1) +
                                         " at " + detail::stampText(last_t) + ")");
            last_t = t;
            if (n_frames_ == 0) {
                o->load();
                // (the catch below names the file)
                K_ = frameFromObservation(*o, "observation 0").K;
                o->unload();
                first_cam = o->cameraParamsIntensity;
                first_calibration = core::CameraIntrinsics::fromMrpt(first_cam);
            } else if (!(core::CameraIntrinsics::fromMrpt(o->cameraParamsIntensity) ==
                         first_calibration)) {
                // (Two rawlogs joined with cat: the frames after the join were tracked with
                // the first camera's model.) The frames before it are the intact part.
                throw std::runtime_error("observation " + std::to_string(n_frames_) + ": " +
                                         cameraChange(o->cameraParamsIntensity, first_cam));
            }
            ++n_frames_;
            progress(std::min(file_bytes, gzip ? control.bytes_read.load() : s.file.getPosition()));
        }
        if (const std::string& gz = checked().damage; !gz.empty())
            throw std::runtime_error("truncated or corrupt gzip stream (" + gz + ")");
        // (the frames before are whole: their gzip member's checksum held)
        if (const std::string& after = checked().trailing; !after.empty())
            throw std::runtime_error(after);
        progress(file_bytes);  // read through
    } catch (const MixedSensors&) {
        throw;
    } catch (const OpeningStopped&) {
        throw;
    } catch (const std::exception& e) {
        damage_ =
            path_ + ": " + e.what() + " after " + std::to_string(n_frames_) + " RGB-D observations";
        // A file cut short keeps the frames before the cut whole. Bytes changed inside a gzip
        // file are found only by its checksum, at its end (or where the decoder trips, later
        // than the change): 3 bytes changed at 5 MB damaged frame 6's pixels, and the break
        // was blamed on the last object, the 31 before it called intact.
        const std::string& gz = checked().damage;
        if (!gz.empty() && gz.find("unexpected end of file") == std::string::npos)
            throw DamagedInput(path_ + ": its gzip data is corrupt (zlib: " + gz +
                                   "), not cut short: no frame of it can be told intact, so "
                                   "none is used (the reading broke with: " +
                                   e.what() + ", after " + std::to_string(n_frames_) +
                                   " RGB-D observations)",
                               0);
        if (!opts_.allow_damaged || n_frames_ == 0) throw DamagedInput(damage_, n_frames_);
    }
    n_skipped_ = skipped;
    format_ = saw_sf ? "action/sensory-frame" : "observations-only";
    if (n_frames_ == 0 && fs::file_size(path_) == 0)
        throw std::runtime_error(path_ + ": an empty file (0 bytes), no rawlog");
    if (n_frames_ == 0)
        throw std::runtime_error(path_ + ": no CObservation3DRangeScan" +
                                 (opts_.sensor_label.empty()
                                      ? std::string()
                                      : " with label '" + opts_.sensor_label + "'") +
                                 " (" + std::to_string(skipped) + " other observations)");
    if (opts_.intrinsics) {
        // As a TUM folder's: intrinsics given for another resolution are refused up front.
        const auto& K = *opts_.intrinsics;
        if (K.width != K_.width || K.height != K_.height)
            throw std::runtime_error(path_ + ": the given camera intrinsics are for " +
                                     std::to_string(K.width) + "x" + std::to_string(K.height) +
                                     " but observation 0's colour image is " +
                                     std::to_string(K_.width) + "x" + std::to_string(K_.height));
        K_ = K;
    }
    stream_ = std::make_unique<Stream>(path_);
    opts_.on_open = nullptr;  // (for the opening only: it may refer to a progress bar now gone)
}

RawlogReader::~RawlogReader() = default;

std::optional<core::Frame> RawlogReader::next() {
    if (n_read_ >= n_frames_) return std::nullopt;
    std::size_t skipped = 0;
    bool sf = false, ob = false;
    // The scan at open counted n_frames_ intact observations: a file that ends or breaks
    // before them was changed since (cut, or written over while it was read). Such a stream
    // cannot go on: the input ends here, and the next call returns nothing.
    const auto broken = [&](const std::string& what) {
        InputBroken error(path_ + ": " + what + " after " + std::to_string(n_read_) + " of the " +
                          std::to_string(n_frames_) +
                          " RGB-D observations it held when opened (changed since?)");
        n_read_ = n_frames_;
        throw error;
    };
    CObservation3DRangeScan::Ptr o;
    try {
        o = stream_->next(opts_.sensor_label, skipped, sf, ob);
    } catch (const std::exception& e) {
        broken(e.what());
    }
    if (!o) broken("ended");
    // Counted before decoding: after a bad observation the next call names the one after it.
    const std::size_t index = n_read_++;
    const std::string what = path_ + " observation " + std::to_string(index);
    mrpt::img::CImage::setImagesPathBase(rawlogImagesDir(path_));
    core::Frame f;
    // The external depth file, "" when the depth is stored inside the rawlog. MRPT reads it
    // with a plain gz read that stops quietly at a cut end, leaving the rest of the depth image
    // unset (zeros or old memory); zlib finds that: `depth_file_damage` is its message, "" for
    // a whole file.
    const std::string depth_file = o->hasRangeImage && o->rangeImage_isExternallyStored()
                                       ? o->rangeImage_getExternalStorageFileAbsolutePath("")
                                       : std::string();
    const auto depth_file_damage = [&]() -> std::string {
        if (depth_file.empty()) return "";
        const std::string gz = core::gzipDamage(depth_file);
        if (gz.empty()) return "";
        return what + ": external depth file '" + depth_file + "' is damaged (" + gz + ")";
    };
    try {
        try {
            o->load();  // external images are decoded here (their presence was checked at open)
        } catch (const std::exception& e) {
            // A depth file cut early or garbled throws in there (load() reads the external
            // depth; the colour image is read when used), with MRPT's message alone ("Cannot
            // read requested number of bytes"): the file is named.
            if (depth_file.empty()) throw;
            const std::string damage = depth_file_damage();
            throw std::runtime_error(!damage.empty() ? damage
                                                     : what + ": external depth file '" +
                                                           depth_file + "' does not decode (" +
                                                           core::innermostMessage(e.what()) + ")");
        }
        if (const std::string damage = depth_file_damage(); !damage.empty())
            throw std::runtime_error(damage);
        f = frameFromObservation(*o, what);
    } catch (const std::exception& e) {
        o->unload();
        const std::string msg = e.what();
        // frameFromObservation's own errors already start with `what`.
        if (msg.rfind(what, 0) == 0) throw;
        throw std::runtime_error(what + ": " + core::innermostMessage(msg));
    }
    o->unload();
    if (opts_.intrinsics) {
        f.K = *opts_.intrinsics;
        core::validateFrame(f, what);  // (a later observation of another size)
    } else if (!(f.K == K_)) {
        // The scan compared the calibrations; an uncalibrated size (ncols 0) takes the
        // image's, which only a decoded image shows.
        throw std::runtime_error(what + ": its colour image is " + std::to_string(f.K.width) +
                                 "x" + std::to_string(f.K.height) + ", observation 0's " +
                                 std::to_string(K_.width) + "x" + std::to_string(K_.height) +
                                 ": a rawlog of one camera is expected");
    }
    f.index = index;
    return f;
}

std::string RawlogReader::describe() const {
    return "rawlog " + path_ + " (" + format_ + ", " + std::to_string(n_frames_) +
           " RGB-D observations" + (damage_.empty() ? "" : ", DAMAGED: " + damage_) + ")";
}

// ---------------------------------------------------------------------------------------
// core::GzOutputStream, not mrpt::io::CFileGZOutputStream: that one's close() ignores a
// disk that filled at the end (see GzOutputStream).
struct RawlogWriter::Stream : public core::GzOutputStream {
    Stream(const std::string& path, int level, bool fresh)
        : GzOutputStream(path, level, "rawlog", fresh) {}
};

RawlogWriter::RawlogWriter(std::string path, RawlogWriterOptions opts)
    : path_(std::move(path)), opts_(std::move(opts)) {
    if (opts_.compression < 0 || opts_.compression > 9)
        throw std::invalid_argument("rawlog compression must be 0..9, got " +
                                    std::to_string(opts_.compression));
    stream_ = std::make_unique<Stream>(path_, opts_.compression, opts_.fresh);
    if (opts_.external_images) {
        images_dir_ = rawlogImagesDir(path_);
        fs::create_directories(images_dir_);
    }
}

RawlogWriter::~RawlogWriter() {
    try {
        close();
    } catch (const std::exception& e) {
        std::fprintf(stderr, "RawlogWriter: %s\n", e.what());
    }
}

void RawlogWriter::write(const core::Frame& f) {
    if (!stream_) throw std::logic_error("RawlogWriter::write after close: " + path_);
    const std::string what = f.rgb_source.empty() ? "frame" : f.rgb_source;
    core::validateFrame(f, what);
    // (rawDepth16 saturates: a 15 m reading at 5000 units per metre was stored as 13.1 m)
    core::requireDepthFits16(f, f.depth_scale, what, "a rawlog's range image");
    auto obs = CObservation3DRangeScan::Create();
    obs->sensorLabel = opts_.sensor_label;
    obs->timestamp = mrpt::Clock::fromDouble(f.timestamp);
    obs->range_is_depth = true;
    obs->hasIntensityImage = true;
    obs->intensityImage = mrpt::img::CImage(f.bgr, mrpt::img::DEEP_COPY);
    obs->intensityImageChannel = CObservation3DRangeScan::CH_VISIBLE;
    const cv::Mat raw = f.rawDepth16();
    obs->rangeImage_setSize(raw.rows, raw.cols);
    for (int r = 0; r < raw.rows; ++r) {
        const auto* src = raw.ptr<uint16_t>(r);
        for (int c = 0; c < raw.cols; ++c) obs->rangeImage(r, c) = src[c];
    }
    obs->hasRangeImage = true;
    obs->rangeUnits = static_cast<float>(1.0 / f.depth_scale);
    obs->maxRange = 65535.0f / static_cast<float>(f.depth_scale);
    obs->cameraParams = f.K.toMrpt();
    obs->cameraParamsIntensity = obs->cameraParams;  // registered
    obs->relativePoseIntensityWRTDepth = opticalInObs();
    if (opts_.external_images) {
        const std::string base = "frame_" + std::to_string(count_);
        mrpt::img::CImage::setImagesPathBase(images_dir_);
        const std::string rgb_path = images_dir_ + "/" + base + "_rgb.png";
        detail::writePng(rgb_path, obs->intensityImage.asCvMatRef());
        obs->intensityImage.setExternalStorage(base + "_rgb.png");
        obs->rangeImage_convertToExternalStorage(base + "_depth.bin", images_dir_ + "/");
        // MRPT writes it through a gz stream that ignores what gzclose() returns (the end of
        // the file leaves zlib's buffers there; see RawlogWriter::Stream): read back whole.
        const std::string depth_path = images_dir_ + "/" + base + "_depth.bin";
        if (const std::string d = core::gzipDamage(depth_path); !d.empty())
            throw std::runtime_error("cannot write '" + depth_path + "': " + d + " (disk full?)");
    }
    auto arch = mrpt::serialization::archiveFrom(static_cast<mrpt::io::CStream&>(*stream_));
    try {
        if (opts_.sensory_frames) {
            mrpt::obs::CActionCollection acts;  // no odometry: an empty action keeps the layout
            mrpt::obs::CSensoryFrame sf;
            sf.insert(obs);
            arch << acts << sf;
        } else {
            arch << *obs;
        }
    } catch (const std::exception& e) {
        // MRPT's message is a stack trace ("Cannot write bytes to stream!"): the system's
        // reason where the stream has one ("No space left on device"), else MRPT's first line,
        // with the file and frame.
        const std::string why = stream_->lastError().empty()
                                    ? core::innermostMessage(e.what()) + " (disk full?)"
                                    : stream_->lastError();
        throw std::runtime_error("cannot write rawlog '" + path_ + "' at " + what + ": " + why);
    }
    ++count_;
}

void RawlogWriter::close() {
    if (!stream_) return;
    const auto stream = std::move(stream_);  // closed once, even when it throws
    stream->close();
}

}  // namespace devslam::io

// ---------------------------------------------------------------------------------------
// MRPT 2.5's mrpt::aligned_malloc (the allocator of its matrices and images) returns nullptr
// when ::aligned_alloc fails, and its containers then write through the null pointer: a
// rawlog whose range-image size field is damaged (rows 0x7fffffff) segfaulted inside
// CObservation3DRangeScan::serializeFrom, before any of our code could look at the size, and
// one claiming 100000 x 100000 pixels made it zero 20 GB before the stream ran out. This
// definition takes the place of libmrpt-core's for every MRPT library in a program that reads
// rawlogs (the program's own symbol interposes the shared library's, as for malloc): the same
// allocation (the size rounded up to the alignment, freed by mrpt::aligned_free's ::free), but
// a failure or a single block over 4 GiB, which no image or map of this project comes near,
// throws std::bad_alloc, which the reader reports as an object that does not decode.
namespace {
class MrptAllocationRefused : public std::bad_alloc {
  public:
    explicit MrptAllocationRefused(std::size_t bytes)
        : msg_("a block of " + std::to_string(bytes) +
               " bytes could not be allocated (a damaged size field?)") {}
    [[nodiscard]] const char* what() const noexcept override { return msg_.c_str(); }

  private:
    std::string msg_;
};
}  // namespace

void* mrpt::aligned_malloc(std::size_t size, std::size_t alignment) {
    constexpr std::size_t kMaxBlock = std::size_t(4) << 30;
    if (alignment != 0 && size % alignment != 0) size = (size / alignment + 1) * alignment;
    if (size > kMaxBlock) throw MrptAllocationRefused(size);
    void* p = ::aligned_alloc(alignment, size);
    if (!p && size > 0) throw MrptAllocationRefused(size);
    return p;
}

// ---------------------------------------------------------------------------------------
// A damaged point count in a 3D scan (its hasPoints3D flag set by one flipped byte, the next
// four bytes read as 1.4e9 points) makes CObservation3DRangeScan::serializeFrom resize its
// std::vector point lists, which allocate through the global operator new, not
// mrpt::aligned_malloc. Some of them allocated and the next failed, and the destructor then
// resized the others to the same size to give them to MRPT's memory pool: std::bad_alloc
// inside a destructor, and the program ended with "terminate called" (or, with the memory
// there, took 21 GB and a minute before the stream ran out). This program-wide replacement
// of operator new is the default one (malloc, the new-handler, std::bad_alloc) except that,
// while the rawlog reader decodes an object (NewBlockCap, this thread only), a block over the
// cap throws at once: the first point list is refused, the others are never made, and the
// destructor has nothing to give back. Its delete is free, as the default's. (Written by hand:
// neither MRPT nor the standard library offers a per-thread allocation limit.) Not in the
// AddressSanitizer build, whose own operator new checks every new against its delete (a
// replacement turns both into malloc and free for the whole program); the test of the cap
// skips itself there.
#ifndef __SANITIZE_ADDRESS__
void* operator new(std::size_t bytes) {
    if (bytes > devslam::io::t_new_block_cap) throw MrptAllocationRefused(bytes);
    if (bytes == 0) bytes = 1;
    for (;;) {
        if (void* p = std::malloc(bytes)) return p;
        const std::new_handler handler = std::get_new_handler();
        if (!handler) throw std::bad_alloc();
        handler();
    }
}
void* operator new[](std::size_t bytes) { return ::operator new(bytes); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
#endif
