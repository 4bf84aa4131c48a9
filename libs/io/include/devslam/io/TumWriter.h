#pragma once
/// Writes frames as a TUM RGB-D folder: rgb/<t>.png, depth/<t>.png (16-bit at TUM's 5000
/// units per metre whatever the source's, so a TUM source round-trips bit-exactly and an
/// OpenNI one's millimetres become 5 units each), rgb.txt, depth.txt, and optionally
/// groundtruth.txt.
///
/// Usage:
///   devslam::io::TumWriter out("out/seq");
///   out.write(frame); ...; out.close();

#include <devslam/core/Frame.h>
#include <devslam/core/Trajectory.h>

#include <cstdio>
#include <memory>
#include <string>

namespace devslam::io {

class TumWriter {
  public:
    /// Creates the folder (and rgb/, depth/); throws if it cannot. `fresh`: the folder must
    /// not hold a sequence yet (rgb.txt made with O_EXCL: of two writers into one folder
    /// started at once, one is refused, "already holds a TUM sequence", instead of both
    /// writing it).
    explicit TumWriter(std::string folder, const std::string& description = "devslam",
                       bool fresh = false);
    ~TumWriter();
    TumWriter(const TumWriter&) = delete;
    TumWriter& operator=(const TumWriter&) = delete;

    /// Depth is written as round(depth * 5000); throws for depth beyond 13.1 m (16 bits),
    /// and for a frame whose (colour or depth) stamp is not after the previous frame's.
    void write(const core::Frame& f);
    void writeGroundTruth(const core::Trajectory& gt);
    void close();
    [[nodiscard]] std::size_t count() const { return count_; }

  private:
    std::string folder_;
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> rgb_list_, depth_list_;
    std::size_t count_ = 0;
    double last_t_ = 0, last_depth_t_ = 0;  // the previous frame's stamps, as written
    std::size_t last_index_ = 0;
};

}  // namespace devslam::io
