#include <devslam/io/TrajectoryIO.h>
#include <devslam/io/TumWriter.h>

#include "TextFile.h"

#include <mrpt/config/CConfigFileMemory.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <fcntl.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace devslam::io {

namespace {
detail::WrittenFile openList(const std::string& path, const std::string& kind,
                             const std::string& description) {
    auto f = detail::openForWriting(path);
    std::fprintf(f.get(), "# %s images\n# %s\n# timestamp filename\n", kind.c_str(),
                 description.c_str());
    return f;
}
}  // namespace

TumWriter::TumWriter(std::string folder, const std::string& description, bool fresh)
    : folder_(std::move(folder)),
      rgb_list_(nullptr, &std::fclose),
      depth_list_(nullptr, &std::fclose) {
    // (folder_ + "/rgb" of an empty name is "/rgb": a sequence was written into /)
    if (folder_.empty()) throw std::invalid_argument("TumWriter: the folder's name is empty");
    std::error_code ec;
    fs::create_directories(folder_ + "/rgb", ec);
    fs::create_directories(folder_ + "/depth", ec);
    if (ec || !fs::is_directory(folder_ + "/depth"))
        throw std::runtime_error("cannot create TUM folder '" + folder_ + "': " + ec.message());
    if (fresh) {
        // Made here, exclusively: the list marks a folder as holding a sequence.
        const int fd = ::open((folder_ + "/rgb.txt").c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
        if (fd < 0)
            throw std::runtime_error("cannot write TUM folder '" + folder_ + "': " +
                                     (errno == EEXIST ? std::string("it already holds a TUM "
                                                                    "sequence (rgb.txt)")
                                                      : std::strerror(errno)));
        ::close(fd);
    }
    rgb_list_ = openList(folder_ + "/rgb.txt", "color", description);
    depth_list_ = openList(folder_ + "/depth.txt", "depth", description);
}

TumWriter::~TumWriter() = default;

void TumWriter::write(const core::Frame& f) {
    if (!rgb_list_) throw std::logic_error("TumWriter::write after close: " + folder_);
    core::validateFrame(f, "frame " + std::to_string(f.index));
    // TUM's depth PNGs hold 5000 units per metre, whatever the source's units (an OpenNI
    // rawlog's millimetres become 5 units each, exactly); a reader of the folder, ours or the
    // TUM tools, knows no other scale.
    constexpr double kTumScale = 5000.0;
    core::requireDepthFits16(f, kTumScale, "frame " + std::to_string(f.index), "a TUM depth PNG");
    if (count_ == 0) {
        // Intrinsics travel with the folder (TumReader reads camera.ini before guessing).
        mrpt::config::CConfigFileMemory cam;
        f.K.saveToConfig(cam, "camera");
        const std::string cam_path = folder_ + "/camera.ini";
        std::ofstream cf(cam_path);
        cf << "# Camera intrinsics of this sequence (pinhole, depth registered to colour).\n"
           << "# fx fy cx cy [px], width height [px], dist = k1 k2 p1 p2 k3 (OpenCV order)\n"
           << cam.getContent();
        cf.close();  // flushed here: a full disk is found now
        if (!cf) throw std::runtime_error("cannot write '" + cam_path + "'");
    }
    const std::string stamp = detail::stampText(f.timestamp);
    // A depth image with its own stamp (a TUM source) keeps it, as TUM names and lists it.
    const std::string depth_stamp = detail::stampText(f.depth_timestamp.value_or(f.timestamp));
    // Images are named by their stamp as written (microseconds): a stamp not after the
    // previous frame's would write over its images, or list them out of order, which
    // TumReader refuses.
    const double t = std::strtod(stamp.c_str(), nullptr),
                 td = std::strtod(depth_stamp.c_str(), nullptr);
    if (count_ > 0 && (!(t > last_t_) || !(td > last_depth_t_))) {
        const bool colour = !(t > last_t_);
        const double before = colour ? last_t_ : last_depth_t_;
        throw std::runtime_error(
            "frame " + std::to_string(f.index) + ": " +
            (colour ? detail::stampNotAfter(t, before, stamp)
                    : detail::stampNotAfter(td, before, depth_stamp, "depth timestamp")) +
            " (previous frame " + std::to_string(last_index_) + " at " +
            detail::stampText(before) + "): a TUM folder's stamps must increase");
    }
    const std::string rgb = "rgb/" + stamp + ".png";
    const std::string depth = "depth/" + depth_stamp + ".png";
    detail::writePng(folder_ + "/" + rgb, f.bgr);
    detail::writePng(folder_ + "/" + depth, f.rawDepth16(kTumScale));
    std::fprintf(rgb_list_.get(), "%s %s\n", stamp.c_str(), rgb.c_str());
    std::fprintf(depth_list_.get(), "%s %s\n", depth_stamp.c_str(), depth.c_str());
    last_t_ = t;
    last_depth_t_ = td;
    last_index_ = f.index;
    ++count_;
}

void TumWriter::writeGroundTruth(const core::Trajectory& gt) {
    writeTumTrajectory(folder_ + "/groundtruth.txt", gt, "ground truth");
}

void TumWriter::close() {
    for (auto* f : {&rgb_list_, &depth_list_}) {
        if (*f) detail::closeWritten(*f, "error writing the lists of '" + folder_ + "'");
    }
}

}  // namespace devslam::io
