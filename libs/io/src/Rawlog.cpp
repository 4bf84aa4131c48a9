#include <devslam/io/Rawlog.h>

#include "TextFile.h"

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

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>


#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <new>
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
cv::Mat depthInDepthCamera(const CObservation3DRangeScan& o) {
    const int H = static_cast<int>(o.rangeImage.rows()), W = static_cast<int>(o.rangeImage.cols());
    const cv::Mat raw(H, W, CV_16UC1, const_cast<uint16_t*>(o.rangeImage.data()));
    cv::Mat m;
    raw.convertTo(m, CV_32F, o.rangeUnits);
    if (!o.range_is_depth) {  // Euclidean range along the pixel ray -> z
        const auto& c = o.cameraParams;
        for (int v = 0; v < H; ++v)
            for (int u = 0; u < W; ++u) {
                const double x = (u - c.cx()) / c.fx(), y = (v - c.cy()) / c.fy();
                m.at<float>(v, u) /= static_cast<float>(std::sqrt(1 + x * x + y * y));
            }
    }
    return m;
}

// Reprojects depth from the depth camera into the colour camera (z-buffered, nearest pixel).
cv::Mat registerDepth(const CObservation3DRangeScan& o, const cv::Mat& depth, int W, int H) {
    const auto& dc = o.cameraParams;
    const auto& ic = o.cameraParamsIntensity;
    // colour optical <- depth optical
    const mrpt::poses::CPose3D T = (o.relativePoseIntensityWRTDepth - opticalInObs());
    const Eigen::Isometry3d Tci = core::toIsometry(T).inverse();
    cv::Mat out(H, W, CV_32F, cv::Scalar(0));
    for (int v = 0; v < depth.rows; ++v)
        for (int u = 0; u < depth.cols; ++u) {
            const float z = depth.at<float>(v, u);
            if (!(z > 0)) continue;
            const Eigen::Vector3d p((u - dc.cx()) * z / dc.fx(), (v - dc.cy()) * z / dc.fy(), z);
            const Eigen::Vector3d q = Tci * p;
            if (q.z() <= 0) continue;
            const int ui = static_cast<int>(std::lround(ic.fx() * q.x() / q.z() + ic.cx()));
            const int vi = static_cast<int>(std::lround(ic.fy() * q.y() / q.z() + ic.cy()));
            if (ui < 0 || vi < 0 || ui >= W || vi >= H) continue;
            auto& d = out.at<float>(vi, ui);
            if (d == 0 || q.z() < d) d = static_cast<float>(q.z());
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
    if (!o.hasIntensityImage || o.intensityImage.isEmpty())
        throw std::runtime_error(what + ": observation has no colour image");
    if (!o.hasRangeImage || o.rangeImage.rows() == 0)
        throw std::runtime_error(what + ": observation has no depth image");
    core::Frame f;
    f.timestamp = mrpt::Clock::toDouble(o.timestamp);
    const cv::Mat& img = o.intensityImage.asCvMatRef();
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
    f.depth_scale = roundedScale(o.rangeUnits);
    // Both cameras' models before any pixel is projected with them: a focal length of 0 or
    // inf (a damaged file) made the SLAM's grid map loop forever, with no error on the way.
    for (const auto& [name, cam, w, h] :
         {std::tuple{"colour", &o.cameraParamsIntensity, f.bgr.cols, f.bgr.rows},
          std::tuple{"depth", &o.cameraParams, static_cast<int>(o.rangeImage.cols()),
                     static_cast<int>(o.rangeImage.rows())}}) {
        auto K = core::CameraIntrinsics::fromMrpt(*cam);
        K.width = w;
        K.height = h;
        if (const std::string p = K.problem(); !p.empty())
            throw std::runtime_error(what + ": " + name + " camera: " + p);
    }
    const cv::Mat depth = depthInDepthCamera(o);
    const bool same_camera = o.doDepthAndIntensityCamerasCoincide() &&
                             o.cameraParams.fx() == o.cameraParamsIntensity.fx() &&
                             o.cameraParams.fy() == o.cameraParamsIntensity.fy() &&
                             o.cameraParams.cx() == o.cameraParamsIntensity.cx() &&
                             o.cameraParams.cy() == o.cameraParamsIntensity.cy() &&
                             depth.size() == f.bgr.size();
    f.depth = same_camera ? depth : registerDepth(o, depth, f.bgr.cols, f.bgr.rows);
    f.K = core::CameraIntrinsics::fromMrpt(o.cameraParamsIntensity);
    f.K.width = f.bgr.cols;
    f.K.height = f.bgr.rows;
    f.rgb_source = what;
    f.depth_source = what;
    core::validateFrame(f, what);
    return f;
}

// ---------------------------------------------------------------------------------------
struct RawlogReader::Stream {
    explicit Stream(const std::string& path)
        : file(path), arch(mrpt::serialization::archiveFrom(file)) {}
    mrpt::io::CFileGZInputStream file;
    mrpt::serialization::CArchiveStreamBase<mrpt::io::CFileGZInputStream> arch;
    std::vector<CObservation3DRangeScan::Ptr> pending;  // from the current sensory frame
    std::size_t objects = 0;

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
                obj = arch.ReadObject();
            } catch (const mrpt::serialization::CExceptionEOF&) {
                if (file.getPosition() == pos && file.checkEOF()) return nullptr;  // clean end
                throw std::runtime_error("truncated object at byte " + std::to_string(pos));
            } catch (const std::exception& e) {
                throw std::runtime_error("cannot decode object " + std::to_string(objects) +
                                         " at byte " + std::to_string(pos) +
                                         " of the uncompressed stream (" +
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

RawlogReader::RawlogReader(std::string path, ReaderOptions opts)
    : path_(std::move(path)), opts_(std::move(opts)) {
    if (!fs::is_regular_file(path_)) throw std::runtime_error(path_ + ": rawlog file not found");
    mrpt::img::CImage::setImagesPathBase(rawlogImagesDir(path_));
    // Scan once: count frames, find damage, take the intrinsics of the first frame.
    std::size_t skipped = 0;
    bool saw_sf = false, saw_obs = false;
    try {
        Stream s(path_);
        double last_t = 0;
        while (auto o = s.next(opts_.sensor_label, skipped, saw_sf, saw_obs)) {
            if (const std::string m = missingExternalFile(*o); !m.empty())
                throw std::runtime_error("observation " + std::to_string(n_frames_) +
                                         ": external file '" + m + "' not found");
            // As in a TUM list: a stamp not after the previous one is refused (the frames
            // before it are the intact part).
            const double t = mrpt::Clock::toDouble(o->timestamp);
            if (n_frames_ > 0 && !(t > last_t))
                throw std::runtime_error(
                    "observation " + std::to_string(n_frames_) + ": " +
                    detail::stampNotAfter(t, last_t, detail::stampText(t)) +
                    " (previous observation " + std::to_string(n_frames_ - 1) + " at " +
                    detail::stampText(last_t) + ")");
            last_t = t;
            if (n_frames_ == 0) {
                o->load();
                K_ = frameFromObservation(*o, path_ + " observation 0").K;
                o->unload();
            }
            ++n_frames_;
        }
        if (const std::string gz = core::gzipDamage(path_); !gz.empty())
            throw std::runtime_error("truncated or corrupt gzip stream (" + gz + ")");
    } catch (const std::exception& e) {
        damage_ =
            path_ + ": " + e.what() + " after " + std::to_string(n_frames_) + " RGB-D observations";
        if (!opts_.allow_damaged || n_frames_ == 0) throw DamagedInput(damage_, n_frames_);
    }
    n_skipped_ = skipped;
    format_ = saw_sf ? "action/sensory-frame" : "observations-only";
    if (n_frames_ == 0)
        throw std::runtime_error(path_ + ": no CObservation3DRangeScan" +
                                 (opts_.sensor_label.empty()
                                      ? std::string()
                                      : " with label '" + opts_.sensor_label + "'") +
                                 " (" + std::to_string(skipped) + " other observations)");
    if (opts_.intrinsics) K_ = *opts_.intrinsics;
    stream_ = std::make_unique<Stream>(path_);
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
    try {
        o->load();  // external images are decoded here (their presence was checked at open)
        // MRPT reads an external depth file with a plain gz read that stops quietly at a cut
        // end, leaving the rest of the depth image unset (zeros or old memory); zlib finds it.
        if (o->hasRangeImage && o->rangeImage_isExternallyStored()) {
            const std::string p = o->rangeImage_getExternalStorageFileAbsolutePath("");
            if (std::string gz = core::gzipDamage(p); !gz.empty()) {
                if (gz.rfind(p + ": ", 0) == 0) gz.erase(0, p.size() + 2);  // zlib names it too
                throw std::runtime_error(what + ": external depth file '" + p + "' is damaged (" +
                                         gz + ")");
            }
        }
        f = frameFromObservation(*o, what);
    } catch (const std::exception& e) {
        o->unload();
        const std::string msg = e.what();
        // frameFromObservation's own errors already start with `what`.
        if (msg.rfind(what, 0) == 0) throw;
        throw std::runtime_error(what + ": " + core::innermostMessage(msg));
    }
    o->unload();
    if (opts_.intrinsics) f.K = *opts_.intrinsics;
    f.index = index;
    return f;
}

std::string RawlogReader::describe() const {
    return "rawlog " + path_ + " (" + format_ + ", " + std::to_string(n_frames_) +
           " RGB-D observations" + (damage_.empty() ? "" : ", DAMAGED: " + damage_) + ")";
}

// ---------------------------------------------------------------------------------------
// Written by hand instead of mrpt::io::CFileGZOutputStream, whose close() ignores what
// gzclose() returns: the last compressed block and the gzip trailer leave zlib's buffers only
// there, so a disk that fills at the end gave a cut rawlog without a word (found when read).
// The same gzip stream otherwise (gzopen "wb<level>", as MRPT opens it).
struct RawlogWriter::Stream : public mrpt::io::CStream {
    Stream(const std::string& path, int level) : path_(path) {
        gz_ = gzopen(path.c_str(), ("wb" + std::to_string(level)).c_str());
        if (gz_ == nullptr) throw std::runtime_error("cannot write rawlog '" + path + "'");
    }
    ~Stream() override {
        if (gz_ != nullptr) gzclose(gz_);
    }
    Stream(const Stream&) = delete;
    Stream& operator=(const Stream&) = delete;
    size_t Read(void*, size_t) override {
        throw std::logic_error("rawlog '" + path_ + "' is open for writing");
    }
    // Whole or nothing: MRPT's archive throws when fewer bytes than asked were written.
    size_t Write(const void* buf, size_t count) override {
        if (gz_ == nullptr) return 0;
        const auto* p = static_cast<const char*>(buf);
        size_t done = 0;
        while (done < count) {
            const auto chunk = static_cast<unsigned>(std::min<size_t>(count - done, 1u << 30));
            const int n = gzwrite(gz_, p + done, chunk);
            if (n <= 0) return done;
            done += static_cast<size_t>(n);
        }
        written_ += done;
        return done;
    }
    uint64_t Seek(int64_t, TSeekOrigin) override {
        throw std::logic_error("rawlog '" + path_ + "': a gzip stream cannot seek");
    }
    uint64_t getTotalBytesCount() const override { return written_; }
    uint64_t getPosition() const override { return written_; }
    /// Flushes zlib's buffers and the trailer; throws if they could not be written.
    void close() {
        if (gz_ == nullptr) return;
        const int rc = gzclose(std::exchange(gz_, nullptr));
        if (rc != Z_OK)
            throw std::runtime_error("error writing rawlog '" + path_ + "': its end was not " +
                                     "written (disk full?), the file is cut short");
    }

  private:
    std::string path_;
    gzFile gz_ = nullptr;
    uint64_t written_ = 0;
};

RawlogWriter::RawlogWriter(std::string path, RawlogWriterOptions opts)
    : path_(std::move(path)), opts_(std::move(opts)) {
    if (opts_.compression < 0 || opts_.compression > 9)
        throw std::invalid_argument("rawlog compression must be 0..9, got " +
                                    std::to_string(opts_.compression));
    stream_ = std::make_unique<Stream>(path_, opts_.compression);
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
    if (opts_.sensory_frames) {
        mrpt::obs::CActionCollection acts;  // no odometry: an empty action keeps the layout
        mrpt::obs::CSensoryFrame sf;
        sf.insert(obs);
        arch << acts << sf;
    } else {
        arch << *obs;
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
