#include <devslam/core/Interrupt.h>
#include <devslam/core/Pose.h>
#include <devslam/io/Rawlog.h>
#include <devslam/io/RgbdReader.h>
#include <devslam/io/TrajectoryIO.h>
#include <devslam/io/TumReader.h>
#include <devslam/io/TumWriter.h>
#include <devslam/io/VideoReader.h>

#include <gtest/gtest.h>
#include <zlib.h>

#include <sys/stat.h>
#include <mrpt/img/CImage.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/serialization/CArchive.h>

#include "Scratch.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <regex>
#include <tuple>
#include <vector>

#include <sys/resource.h>

namespace fs = std::filesystem;
using namespace devslam;

namespace {

const std::string kTum = std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37";
const std::string kMrptRgbd = "/usr/share/mrpt/datasets/tests_rgbd.rawlog";  // mrpt-common

struct TempDir : devslam::test::TempDir {  // a fresh scratch folder per test
    TempDir() : devslam::test::TempDir("devslam_io_") {}
};

// Copies the first `n` associated frames of the shipped TUM folder into `dst`.
void copyTumSubset(const std::string& dst, std::size_t n) {
    io::TumReader in(kTum);
    io::TumWriter out(dst, "test subset");
    for (std::size_t i = 0; i < n; ++i) out.write(in.read(i));
    out.close();
}

void writeText(const std::string& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

std::string readBytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

// Runs f, expects an E (std::runtime_error unless given) whose message matches `pattern`
// (ECMAScript regex).
template <class E = std::runtime_error, class F>
void expectError(F&& f, const std::string& pattern) {
    try {
        f();
        ADD_FAILURE() << "expected an error matching '" << pattern << "'";
    } catch (const E& e) {
        EXPECT_TRUE(std::regex_search(e.what(), std::regex(pattern)))
            << "message: " << e.what() << "\npattern: " << pattern;
    }
}

void expectFramesEqual(const core::Frame& a, const core::Frame& b) {
    EXPECT_NEAR(a.timestamp, b.timestamp, 1e-6);
    ASSERT_EQ(a.bgr.size(), b.bgr.size());
    EXPECT_EQ(cv::norm(a.bgr, b.bgr, cv::NORM_INF), 0.0) << "colour differs";
    EXPECT_EQ(cv::norm(a.rawDepth16(), b.rawDepth16(), cv::NORM_INF), 0.0) << "raw depth differs";
    EXPECT_EQ(a.K, b.K);
}

/// The frames of a damaged rawlog read with allow_damaged: its intact part, which must be
/// `n` frames (counted at open and read).
std::vector<core::Frame> intactFrames(const std::string& path, std::size_t n) {
    io::ReaderOptions allow;
    allow.allow_damaged = true;
    io::RawlogReader partial(path, allow);
    EXPECT_EQ(partial.size(), n) << path;
    std::vector<core::Frame> frames;
    while (auto f = partial.next()) frames.push_back(std::move(*f));
    EXPECT_EQ(frames.size(), n) << path;
    return frames;
}

/// Writes the first `n` shipped TUM frames as a rawlog at `path`.
void writeShippedRawlog(const std::string& path, std::size_t n,
                        const io::RawlogWriterOptions& wo = {}) {
    io::TumReader tum(kTum);
    io::RawlogWriter w(path, wo);
    for (std::size_t i = 0; i < n; ++i) w.write(tum.read(i));
    w.close();
}

}  // namespace

// ---------------------------------------------------------------- TUM folders
TEST(TumReader, ReadsShippedFramesLikeAssociatePy) {
    io::TumReader r(kTum);
    // 37 colour and 37 depth images; associate.py (max_difference 0.02) pairs 32 of them.
    EXPECT_EQ(r.size(), 32u);
    EXPECT_EQ(r.intrinsics(), core::CameraIntrinsics::fromPreset("freiburg1"));  // from the name
    ASSERT_TRUE(r.groundTruth().has_value());
    EXPECT_EQ(r.groundTruth()->size(), 3000u);
    const core::Frame f = r.read(0);
    EXPECT_NEAR(f.timestamp, 1305031102.175304, 1e-6);
    // The depth image's own stamp (depth.txt), for the SLAM's depth-time compensation; a
    // TUM copy keeps it (the name and the list's stamp).
    ASSERT_TRUE(f.depth_timestamp.has_value());
    EXPECT_NEAR(*f.depth_timestamp, 1305031102.160407, 1e-6);
    {
        TempDir d;
        copyTumSubset(d.str("copy"), 2);
        const auto g = io::TumReader(d.str("copy")).read(0);
        ASSERT_TRUE(g.depth_timestamp.has_value());
        EXPECT_NEAR(*g.depth_timestamp, 1305031102.160407, 1e-6);
        EXPECT_NE(g.depth_source.find("1305031102.160407.png"), std::string::npos);
    }
    EXPECT_EQ(f.bgr.type(), CV_8UC3);
    EXPECT_EQ(f.depth.type(), CV_32FC1);
    EXPECT_EQ(f.bgr.size(), cv::Size(640, 480));
    // depth [m] == raw PNG value / 5000
    const cv::Mat raw = cv::imread(f.depth_source, cv::IMREAD_UNCHANGED);
    ASSERT_EQ(raw.type(), CV_16UC1) << f.depth_source;
    ASSERT_EQ(raw.size(), f.depth.size());
    for (auto [u, v] : {std::pair{320, 240}, {100, 400}, {600, 50}})
        EXPECT_FLOAT_EQ(f.depth.at<float>(v, u), raw.at<uint16_t>(v, u) / 5000.0f);
    EXPECT_EQ(cv::countNonZero(raw == 0), cv::countNonZero(f.depth == 0.0f));  // 0 = missing
    std::size_t n = 0;
    while (auto g = r.next()) EXPECT_EQ(g->index, n++);
    EXPECT_EQ(n, 32u);
}

TEST(TumReader, CameraSelection) {
    EXPECT_EQ(io::tumPresetFromName("/x/rgbd_dataset_freiburg3_walking_xyz"), "freiburg3");
    EXPECT_EQ(io::tumPresetFromName("fr2_desk/"), "freiburg2");
    EXPECT_FALSE(io::tumPresetFromName("my_sequence").has_value());
    io::ReaderOptions o;
    o.camera = "freiburg3";
    EXPECT_EQ(io::TumReader(kTum, o).intrinsics().fx, 535.4);
    o.camera = "nonsense";
    EXPECT_THROW(io::TumReader(kTum, o), std::invalid_argument);
}

TEST(TumReader, MalformedListsNameFileAndLine) {
    TempDir d;
    copyTumSubset(d.str("s"), 3);
    const std::string rgb = d.str("s/rgb.txt");
    std::ifstream in(rgb);
    std::string header, l1, l2, l3, line;
    for (int k = 0; k < 3; ++k) std::getline(in, line), header += line + "\n";
    std::getline(in, l1), std::getline(in, l2), std::getline(in, l3);
    in.close();

    // A ground truth file that holds no pose, or a bad one, says how to run without it.
    writeText(d.str("s/groundtruth.txt"), "# timestamp tx ty tz qx qy qz qw\n");
    expectError([&] { io::TumReader r(d.str("s")); },
                "groundtruth\\.txt: no poses \\(a folder without groundtruth\\.txt runs without "
                "ATE\\)");
    writeText(d.str("s/groundtruth.txt"), "1305031102.2 1 2 3\n");
    expectError([&] { io::TumReader r(d.str("s")); },
                "groundtruth\\.txt line 1: expected .* \\(a folder without groundtruth");
    fs::remove(d.str("s/groundtruth.txt"));
    writeText(rgb, header + l1 + "\n" + "1305031102.2 rgb/a.png extra\n" + l3 + "\n");
    expectError([&] { io::TumReader r(d.str("s")); },
                "rgb\\.txt line 5: expected 'timestamp filename'");
    writeText(rgb, header + l1 + "\nabc rgb/x.png\n");
    expectError([&] { io::TumReader r(d.str("s")); },
                "rgb\\.txt line 5: timestamp 'abc' is not a number");
    // A NUL inside a file name: the name was opened cut at it, without a word.
    writeText(rgb, header + l1 + "\n" + l2 + std::string(1, '\0') + "junk\n");
    expectError([&] { io::TumReader r(d.str("s")); },
                "rgb\\.txt line 5: control byte 0x00 \\(not a text file\\?\\)");
    writeText(rgb, header + l2 + "\n" + l1 + "\n");
    expectError([&] { io::TumReader r(d.str("s")); }, "rgb\\.txt line 5: unsorted timestamp");
    writeText(rgb, header + l1 + "\n" + l1 + "\n");
    expectError([&] { io::TumReader r(d.str("s")); }, "rgb\\.txt line 5: duplicate timestamp");
    // One image under two stamps (two frames of one picture), stamps no clock gives (they
    // only left their frame unpaired), a line of megabytes (read whole into memory).
    const std::string l1_file = l1.substr(l1.find(' ') + 1);
    writeText(rgb, header + l1 + "\n" + "1305031102.9 " + l1_file + "\n");
    expectError([&] { io::TumReader r(d.str("s")); },
                "rgb\\.txt line 5: '" + l1_file + "' is listed again \\(first at line 4\\)");
    writeText(rgb, header + "-1 rgb/x.png\n");
    expectError([&] { io::TumReader r(d.str("s")); },
                "rgb\\.txt line 4: timestamp -1 is not in \\[0, 1e11\\] s");
    writeText(rgb, header + l1 + "\n" + std::string(100000, '1') + " rgb/x.png\n");
    expectError([&] { io::TumReader r(d.str("s")); },
                "rgb\\.txt line 5: longer than 64 KiB \\(not a text file of lines\\?\\)");
    // A folder, or a pipe (which blocked the reader for ever at its opening), where a list is.
    fs::remove(rgb);
    fs::create_directory(rgb);
    expectError([&] { io::TumReader r(d.str("s")); }, "rgb\\.txt: file is a folder, not a file");
    fs::remove(rgb);
    ASSERT_EQ(::mkfifo(rgb.c_str(), 0600), 0);
    expectError([&] { io::TumReader r(d.str("s")); },
                "rgb\\.txt: file is a pipe or device, not a file");
    fs::remove(rgb);
    // Lists that share no stamp (10 s apart): what each holds, to tell two recordings apart
    writeText(rgb, header + "1305031112.2 rgb/x.png\n");
    expectError([&] { io::TumReader r(d.str("s")); },
                "no rgb/depth pair within 0\\.02 s \\(rgb\\.txt: 1 image, stamps "
                "1305031112\\.200000 to 1305031112\\.200000; depth\\.txt: 3 images, stamps "
                "1305031102\\.[0-9]+ to 1305031102\\.[0-9]+\\)$");
    writeText(rgb, header);
    expectError([&] { io::TumReader r(d.str("s")); }, "rgb\\.txt: no entries");
    fs::remove(rgb);
    expectError([&] { (void)io::openRgbd(d.str("s")); }, "no rgb\\.txt");
    expectError([&] { io::TumReader r(d.str("s")); }, "rgb\\.txt: file not found");
    expectError([&] { (void)io::openRgbd(d.str("nothing_here")); }, "no such TUM folder or rawlog");
    // The system's reason, after the path, where the path cannot be looked at (it was a bare
    // "filesystem error: status: File name too long [...]").
    const std::string long_name = d.str(std::string(300, 'a'));
    expectError([&] { (void)io::openRgbd(long_name); }, "^" + long_name + ": File name too long$");
    writeText(d.str("plain"), "x");  // a path through a file: not there, as ENOENT
    expectError([&] { (void)io::openRgbd(d.str("plain/x")); }, "no such TUM folder or rawlog");
    // There, but neither (it was "no such"); and an empty name.
    expectError([&] { (void)io::openRgbd("/dev/null"); },
                "^/dev/null: neither a TUM folder nor a rawlog file$");
    expectError([&] { (void)io::openRgbd(""); }, "^the input's name is empty");
}

// Lists as other tools write them: a byte-order mark and CRLF (Windows editors), an image
// given by its absolute path (it was looked for under the folder), a '#' inside a file name
// (it was cut there as a comment; TUM's associate.py keeps it), a comment after the values.
TEST(TumReader, ListsFromOtherToolsReadAsTheTumToolsReadThem) {
    TempDir d;
    copyTumSubset(d.str("s"), 2);
    std::vector<core::Frame> plain;
    {
        io::TumReader r(d.str("s"));
        for (std::size_t i = 0; i < r.size(); ++i) plain.push_back(r.read(i));
    }
    std::vector<std::string> rgb_lines;
    {
        std::ifstream in(d.str("s/rgb.txt"));
        for (std::string line; std::getline(in, line);)
            if (!line.empty() && line[0] != '#') rgb_lines.push_back(line);
    }
    ASSERT_EQ(rgb_lines.size(), 2u);
    const auto name = [](const std::string& l) { return l.substr(l.find(' ') + 1); };
    const auto stamp = [](const std::string& l) { return l.substr(0, l.find(' ')); };
    fs::rename(d.str("s/" + name(rgb_lines[1])), d.str("s/rgb/take#2.png"));
    writeText(d.str("s/rgb.txt"), "\xEF\xBB\xBF# colour images\r\n" + stamp(rgb_lines[0]) + " " +
                                      d.str("s/" + name(rgb_lines[0])) + "  # absolute\r\n" +
                                      stamp(rgb_lines[1]) + " rgb/take#2.png\r\n");
    std::string depth;
    {
        std::ifstream in(d.str("s/depth.txt"));
        std::stringstream ss;
        ss << in.rdbuf();
        depth = ss.str();
    }
    writeText(d.str("s/depth.txt"), "\xEF\xBB\xBF" + depth);
    io::TumReader odd(d.str("s"));
    ASSERT_EQ(odd.size(), plain.size());
    for (std::size_t i = 0; i < odd.size(); ++i) {
        const auto &a = plain[i], b = odd.read(i);
        EXPECT_EQ(a.timestamp, b.timestamp) << i;
        EXPECT_EQ(cv::norm(a.bgr, b.bgr, cv::NORM_INF), 0.0) << i;
        EXPECT_EQ(cv::norm(a.depth, b.depth, cv::NORM_INF), 0.0) << i;
    }
    EXPECT_EQ(odd.read(1).rgb_source, d.str("s") + "/rgb/take#2.png");
}

// devslam-convert's writers make their output exclusively: of two conversions into one
// output started at once, one was refused only by a check both passed, and both wrote it
// (a rawlog that did not decode, both saying "wrote 5 frames").
TEST(Writers, FreshOutputsRefuseOneThatIsThere) {
    TempDir d;
    const std::string rawlog = d.str("a.rawlog");
    writeText(rawlog, "made by another run");
    io::RawlogWriterOptions wo;
    wo.fresh = true;
    expectError([&] { io::RawlogWriter w(rawlog, wo); },
                "^cannot write rawlog '.*a\\.rawlog': File exists$");
    wo.fresh = false;
    EXPECT_NO_THROW(io::RawlogWriter(rawlog, wo).close());
    copyTumSubset(d.str("tum"), 1);
    expectError(
        [&] { io::TumWriter w(d.str("tum"), "x", true); },
        "^cannot write TUM folder '.*tum': it already holds a TUM sequence \\(rgb\\.txt\\)$");
    EXPECT_NO_THROW(io::TumWriter(d.str("tum"), "x", false).close());
    EXPECT_NO_THROW(io::TumWriter(d.str("new"), "x", true).close());
}

TEST(TumReader, BadImagesNameTheFile) {
    TempDir d;
    copyTumSubset(d.str("s"), 3);
    io::TumReader ok(d.str("s"));
    const core::Frame f0 = ok.read(0), f1 = ok.read(1), f2 = ok.read(2);

    // A listed image that does not exist: caught when opening, with list file and line.
    fs::remove(f2.rgb_source);
    expectError(
        [&] { io::TumReader r(d.str("s")); },
        "rgb\\.txt line 6: image 'rgb/.*\\.png' not found; 1 of 3 rgb-depth pairs left out");
    try {
        io::TumReader r(d.str("s"));
        ADD_FAILURE() << "opened";
    } catch (const io::DamagedInput& e) {
        EXPECT_EQ(e.intact(), 2u);
    } catch (const std::exception& e) {
        ADD_FAILURE() << "not io::DamagedInput: " << e.what();
    }
    // With allow_damaged the pairs whose images exist are read, and damage() says what not.
    io::ReaderOptions allow;
    allow.allow_damaged = true;
    fs::remove(f0.depth_source);
    {
        io::TumReader partial(d.str("s"), allow);
        EXPECT_EQ(partial.size(), 1u);
        EXPECT_TRUE(std::regex_search(
            partial.damage(),
            std::regex("depth\\.txt line 4: image 'depth/.*' not found \\(and 1 more missing "
                       "images\\); 2 of 3 rgb-depth pairs left out")))
            << partial.damage();
        const auto f = partial.next();
        ASSERT_TRUE(f.has_value());
        EXPECT_EQ(f->rgb_source, f1.rgb_source);
        EXPECT_FALSE(partial.next().has_value());
    }
    cv::Mat raw;
    f0.depth.convertTo(raw, CV_16U, f0.depth_scale);
    ASSERT_TRUE(cv::imwrite(f0.depth_source, raw));  // restored for the checks below
    // An image that does not decode.
    writeText(f2.rgb_source, "this is not a png");
    expectError([&] { (void)io::TumReader(d.str("s")).read(2); },
                "\\.png: cannot decode colour image");
    // Depth of the wrong type (8-bit) and of the wrong size.
    cv::imwrite(f1.depth_source, cv::Mat(480, 640, CV_8UC1, cv::Scalar(7)));
    expectError([&] { (void)io::TumReader(d.str("s")).read(1); }, "depth must be a 16-bit");
    cv::imwrite(f0.depth_source, cv::Mat(240, 320, CV_16UC1, cv::Scalar(7)));
    expectError([&] { (void)io::TumReader(d.str("s")).read(0); },
                "depth is 320x240 but .* is 640x480");
}

TEST(TumReader, CameraIniNamesItsMistakes) {
    TempDir d;
    copyTumSubset(d.str("s"), 2);
    io::ReaderOptions ro;  // camera "auto": the folder's camera.ini comes first
    writeText(d.str("s") + "/camera.ini", "[camera]\nfx = 500\nfy = 500\ncx = 320\ncy = 240\n");
    EXPECT_NEAR(io::TumReader(d.str("s"), ro).intrinsics().fx, 500.0, 1e-12);
    writeText(d.str("s") + "/camera.ini", "[camra]\nfx = 500\nfy = 500\ncx = 320\ncy = 240\n");
    expectError([&] { io::TumReader r(d.str("s"), ro); },
                "camera\\.ini: unknown section \\[camra\\] \\(known: camera\\)");
    writeText(d.str("s") + "/camera.ini", "[camera]\nfx = 500\n");
    expectError([&] { io::TumReader r(d.str("s"), ro); }, "camera\\.ini: .*fy: required key");
}

// ---------------------------------------------------------------- trajectories
TEST(TrajectoryIO, RoundTripAndErrors) {
    TempDir d;
    const auto gt = io::readTumTrajectory(kTum + "/groundtruth.txt");
    ASSERT_EQ(gt.size(), 3000u);
    EXPECT_NEAR(gt.front().t, 1305031098.6659, 1e-9);
    EXPECT_NEAR(gt.front().pose.x(), 1.3563, 1e-12);
    io::writeTumTrajectory(d.str("t.txt"), gt);
    const auto back = io::readTumTrajectory(d.str("t.txt"));
    ASSERT_EQ(back.size(), gt.size());
    for (std::size_t i = 0; i < gt.size(); i += 97) {
        EXPECT_NEAR(back[i].t, gt[i].t, 1e-6);
        EXPECT_LT((back[i].pose - gt[i].pose).norm(), 1e-8);
        EXPECT_LT(core::rotationAngle(back[i].pose - gt[i].pose), 1e-8);
    }
    writeText(d.str("bad.txt"), "# c\n1 0 0 0 0 0 0 1\n2 0 0 0 0 0 1\n");
    expectError([&] { (void)io::readTumTrajectory(d.str("bad.txt")); },
                "bad\\.txt line 3: expected .*got 7");
    writeText(d.str("bad.txt"), "1 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n");
    expectError([&] { (void)io::readTumTrajectory(d.str("bad.txt")); },
                "line 2: duplicate timestamp 1 \\(previous pose at line 1\\)");
    // A stamp out of range is named on its own line (1e300 was read, and the next line was
    // blamed for coming before it).
    writeText(d.str("bad.txt"), "1 0 0 0 0 0 0 1\n# x\n1e300 0 0 0 0 0 0 1\n3 0 0 0 0 0 0 1\n");
    expectError([&] { (void)io::readTumTrajectory(d.str("bad.txt")); },
                "line 3: timestamp 1e300 is not in \\[0, 1e11\\] s");
    writeText(d.str("bad.txt"), "-5 0 0 0 0 0 0 1\n");
    expectError([&] { (void)io::readTumTrajectory(d.str("bad.txt")); },
                "line 1: timestamp -5 is not in \\[0, 1e11\\] s");
    writeText(d.str("bad.txt"), "5 0 0 0 0 0 0 1\n\n4 0 0 0 0 0 0 1\n");
    expectError([&] { (void)io::readTumTrajectory(d.str("bad.txt")); },
                "line 3: unsorted timestamp 4 \\(previous pose at line 1\\)");
    writeText(d.str("bad.txt"), "1 0 0 0 0 0 0 3\n");
    expectError([&] { (void)io::readTumTrajectory(d.str("bad.txt")); }, "line 1: quaternion norm");
    // The TUM tools' float() reads no hexadecimal (std::stod did: 0x1p-3 was 0.125).
    writeText(d.str("bad.txt"), "1 0x1p-3 0 0 0 0 0 1\n");
    expectError([&] { (void)io::readTumTrajectory(d.str("bad.txt")); },
                "line 1: tx '0x1p-3' is not a number");
    // ... but reads an underflowing number as the TUM tools do (std::stod threw on it).
    writeText(d.str("tiny.txt"), "1 0 0 0 1e-320 0 0 1\n2 0 0 1e-400 0 0 0 1\n");
    const auto tiny = io::readTumTrajectory(d.str("tiny.txt"));
    ASSERT_EQ(tiny.size(), 2u);
    EXPECT_EQ(tiny[1].pose.z(), 0.0);
    writeText(d.str("bad.txt"), "1 1e400 0 0 0 0 0 1\n");
    expectError([&] { (void)io::readTumTrajectory(d.str("bad.txt")); },
                "line 1: tx '1e400' is not a number");
    writeText(d.str("bad.txt"), "# only comments\n");
    expectError([&] { (void)io::readTumTrajectory(d.str("bad.txt")); }, "no poses");
    expectError([&] { (void)io::readTumTrajectory(d.str("missing.txt")); }, "cannot open");
    // A full disk: two poses fit the write buffer, which goes out (and fails) at the close;
    // that was not checked, and the lost file passed for written.
    EXPECT_TRUE(fs::exists("/dev/full")) << "Linux has /dev/full: the write error is not tested";
    if (fs::exists("/dev/full"))
        expectError(
            [&] {
                io::writeTumTrajectory("/dev/full", {gt[0], gt[1]});
            },
            "error writing '/dev/full'");
}

// ---------------------------------------------------------------- rawlogs
class RawlogRoundTrip : public ::testing::TestWithParam<std::pair<bool, bool>> {};

TEST_P(RawlogRoundTrip, AllRealFramesBitExact) {
    const auto [sensory_frames, external] = GetParam();
    TempDir d;
    io::TumReader tum(kTum);
    // Every real frame in the default layout; the other layouts on a few (saves CI time).
    const std::size_t n = (sensory_frames || external) ? 4 : *tum.size();
    io::RawlogWriterOptions wo;
    wo.sensory_frames = sensory_frames;
    wo.external_images = external;
    const std::string path = d.str("seq.rawlog");
    {
        io::RawlogWriter w(path, wo);
        for (std::size_t i = 0; i < n; ++i) w.write(tum.read(i));
        w.close();
        EXPECT_EQ(w.count(), n);
    }
    if (external) {
        EXPECT_TRUE(fs::exists(d.str("seq_Images")));
    }
    io::RawlogReader r(path);
    EXPECT_EQ(r.size(), n);
    EXPECT_TRUE(r.damage().empty());
    EXPECT_EQ(r.format(), sensory_frames ? "action/sensory-frame" : "observations-only");
    std::size_t i = 0;
    while (auto f = r.next()) expectFramesEqual(*f, tum.read(i++));
    EXPECT_EQ(i, n);

    // ... and back to a TUM folder: images identical to the originals, pixel for pixel.
    {
        io::RawlogReader again(path);
        io::TumWriter out(d.str("back"));
        while (auto f = again.next()) out.write(*f);
        out.close();
    }
    io::TumReader back(d.str("back"));
    ASSERT_EQ(back.size(), n);
    EXPECT_NE(back.describe().find("camera.ini"), std::string::npos);
    for (std::size_t k = 0; k < n; ++k) {
        const auto a = tum.read(k), b = back.read(k);
        expectFramesEqual(a, b);
        const cv::Mat ra = cv::imread(a.depth_source, cv::IMREAD_UNCHANGED);
        const cv::Mat rb = cv::imread(b.depth_source, cv::IMREAD_UNCHANGED);
        EXPECT_EQ(cv::norm(ra, rb, cv::NORM_INF), 0.0);
    }
}

INSTANTIATE_TEST_SUITE_P(Layouts, RawlogRoundTrip,
                         ::testing::Values(std::pair{false, false}, std::pair{true, false},

                                           std::pair{false, true}));

TEST(Rawlog, MrptsRawlogEditReadsOurFiles) {
    TempDir d;
    copyTumSubset(d.str("s"), 5);
    const std::string path = d.str("five.rawlog");
    const std::string cmd = std::string(DEVSLAM_BIN_DIR) + "/devslam-convert " + d.str("s") + " " +
                            path + " --sensory-frames > " + d.str("c.log") + " 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    const std::string info = d.str("info.txt");
    ASSERT_EQ(std::system(("rawlog-edit --info -i " + path + " > " + info + " 2>&1").c_str()), 0)
        << "rawlog-edit (Debian package mrpt-apps) must be installed and read the file";
    std::ifstream in(info);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_TRUE(std::regex_search(text, std::regex("RGBD\\s*/\\s*5\\s*/"))) << text;
    EXPECT_TRUE(std::regex_search(text, std::regex("Actions/SensoryFrame format\\s*:\\s*Yes")))
        << text;
    // A rawlog's observations carry their camera: --camera on one is refused, not ignored.
    const std::string again = std::string(DEVSLAM_BIN_DIR) + "/devslam-convert " + path + " " +
                              d.str("again.rawlog") + " --camera freiburg2 > " + d.str("c2.log") +
                              " 2>&1";
    EXPECT_NE(std::system(again.c_str()), 0) << again;
    std::ifstream log(d.str("c2.log"));
    const std::string said((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
    EXPECT_NE(said.find("--camera freiburg2: '" + path + "' is a rawlog"), std::string::npos)
        << said;
    EXPECT_FALSE(fs::exists(d.str("again.rawlog")));
}

TEST(Rawlog, TruncatedFileReportsWhatWasRead) {
    TempDir d;
    copyTumSubset(d.str("s"), 6);
    const std::string path = d.str("six.rawlog");
    {
        io::RawlogWriter w(path, {});
        io::TumReader tum(d.str("s"));
        while (auto f = tum.next()) w.write(*f);
    }
    // Bytes changed inside the file (not cut): gzip finds it only by its checksum at the end,
    // so frames before the break may hold changed pixels (3 bytes at 5 MB changed frame 6 of
    // 32, and the 31 before the break were called intact). None is used, even when asked.
    const std::string flipped = d.str("flipped.rawlog");
    fs::copy_file(path, flipped);
    {
        std::fstream f(flipped, std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(std::streamoff(fs::file_size(flipped) / 3));
        f.write("\xff\x00\x55", 3);
    }
    for (const bool allow_damaged : {false, true}) {
        io::ReaderOptions o;
        o.allow_damaged = allow_damaged;
        try {
            (void)io::openRgbd(flipped, o);
            ADD_FAILURE() << "a rawlog with changed bytes opened";
        } catch (const io::DamagedInput& e) {
            EXPECT_EQ(e.intact(), 0u) << e.what();
            EXPECT_TRUE(std::regex_search(
                e.what(), std::regex("flipped\\.rawlog: its gzip data is corrupt \\(zlib: [^)]+\\), "
                                     "not cut short: no frame of it can be told intact")))
                << e.what();
        }
    }
    // Something after the whole gzip stream: zlib ends there without a word, so a second
    // rawlog appended with a damaged first byte (its frames), or junk, was lost silently. The
    // frames before it are whole (their member's checksum held).
    const auto whole = readBytes(path);
    for (const std::string& tail :
         {std::string(1000, '\0'), std::string("junk"), "\x1e" + whole.substr(1)}) {
        const std::string joined = d.str("joined.rawlog");
        writeText(joined, whole + tail);
        try {
            (void)io::openRgbd(joined);
            ADD_FAILURE() << "a rawlog with " << tail.size() << " bytes after it opened";
        } catch (const io::DamagedInput& e) {
            EXPECT_EQ(e.intact(), 6u) << e.what();
            EXPECT_EQ(std::string(e.what()),
                      joined + ": " + std::to_string(tail.size()) +
                          " bytes after the end of its gzip data at byte " +
                          std::to_string(whole.size()) +
                          " are no gzip stream (another file appended, or damage) after 6 RGB-D "
                          "observations");
        }
        io::ReaderOptions o;
        o.allow_damaged = true;
        EXPECT_EQ(io::openRgbd(joined, o)->size(), 6u);
    }
    {  // a second whole member is read on (two rawlogs joined with cat): its frames come after
        const std::string joined = d.str("joined.rawlog");
        writeText(joined, whole + whole);
        expectError([&] { (void)io::openRgbd(joined); }, "observation 6: unsorted timestamp");
    }
    // Cut the file in the middle of the 4th observation (observations are similar in size).
    const auto size = fs::file_size(path);
    fs::resize_file(path, size * 7 / 12);
    expectError([&] { io::RawlogReader r(path); }, "six\\.rawlog: .* after 3 RGB-D observations");
    try {
        (void)io::openRgbd(path);
        ADD_FAILURE() << "a truncated rawlog opened";
    } catch (const io::DamagedInput& e) {
        EXPECT_EQ(e.intact(), 3u) << e.what();
    }
    io::ReaderOptions allow;
    allow.allow_damaged = true;
    const auto partial = io::openRgbd(path, allow);
    EXPECT_EQ(partial->size(), 3u);
    EXPECT_TRUE(std::regex_search(partial->damage(),
                                  std::regex("six\\.rawlog: .* after 3 RGB-D observations")))
        << partial->damage();
    EXPECT_NE(partial->describe().find("DAMAGED"), std::string::npos) << partial->describe();
    std::size_t n = 0;
    while (partial->next()) ++n;
    EXPECT_EQ(n, 3u);
    // Cut inside the first observation: a truncated rawlog, not "not a rawlog?" (MRPT 2's
    // class names start "mrpt::obs::", which the check for a rawlog's start did not know).
    fs::resize_file(path, size / 12);
    try {
        io::RawlogReader r(path);
        ADD_FAILURE() << "a rawlog cut in its first observation opened";
    } catch (const std::exception& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("truncated object at byte 0"), std::string::npos) << m;
        EXPECT_EQ(m.find("not a rawlog"), std::string::npos) << m;
    }
    // Cut inside the gzip header: nothing decodes, and the error says so.
    fs::resize_file(path, 60);
    expectError([&] { io::RawlogReader r(path); }, "truncated or corrupt gzip stream .* after 0");
    writeText(path, "garbage");
    expectError([&] { io::RawlogReader r(path); }, "cannot decode object 0 at byte 0");
    expectError([&] { io::RawlogReader r(d.str("none.rawlog")); }, "rawlog file not found");
}

// A rawlog cut after it was opened (the scan at open found it whole) is an error naming the
// file, not a quiet early end that would pass for a shorter sequence.
TEST(Rawlog, FileCutAfterOpeningIsAnError) {
    TempDir d;
    const std::string path = d.str("cut.rawlog");
    writeShippedRawlog(path, 6);
    io::RawlogReader r(path);
    ASSERT_EQ(r.size(), 6u);
    fs::resize_file(path, fs::file_size(path) / 2);
    std::size_t read = 0;
    try {
        while (r.next()) ++read;
        FAIL() << "the cut file ended quietly after " << read << " frames";
    } catch (const io::InputBroken& e) {  // not a damaged frame that could be passed
        const std::string m = e.what();
        EXPECT_EQ(m.rfind(path + ": ", 0), 0u) << m;
        EXPECT_NE(m.find(" of the 6 RGB-D observations it held when opened (changed since?)"),
                  std::string::npos)
            << m;
    }
    EXPECT_LT(read, 6u);
    // The broken stream cannot go on: the next call ends the input, and does not throw the
    // same error forever (devslam-convert --allow-damaged looped on it, growing).
    EXPECT_FALSE(r.next().has_value());
}

// Opening reads the whole rawlog (frames counted, zlib's check beside): a progress bar is
// told each frame found and how far into the file's bytes the check is, ending with all of
// them; an input that opens at once draws no bar, and a TUM folder never calls it.
TEST(Rawlog, OpeningTellsItsProgress) {
    TempDir d;
    const std::string path = d.str("six.rawlog");
    writeShippedRawlog(path, 6);
    std::vector<std::size_t> frames;
    std::uint64_t last_read = 0, total = 0;
    bool bytes_in_order = true;
    const auto count = [&](std::size_t n, std::uint64_t read, std::uint64_t of) {
        frames.push_back(n);
        bytes_in_order = bytes_in_order && read >= last_read && read <= of;
        last_read = read;
        total = of;
        return true;
    };
    io::ReaderOptions ro;
    std::FILE* out = std::tmpfile();
    ASSERT_NE(out, nullptr);
    {
        io::OpenProgressBar bar(path, out);
        ro.on_open = [&, cb = bar.callback()](std::size_t n, std::uint64_t r, std::uint64_t of) {
            return count(n, r, of) && cb(n, r, of);
        };
        const auto reader = io::openRgbd(path, ro);
        bar.finish();
        EXPECT_EQ(reader->size(), 6u);
    }
    EXPECT_EQ(frames, (std::vector<std::size_t>{1, 2, 3, 4, 5, 6, 6}));
    EXPECT_TRUE(bytes_in_order);
    EXPECT_EQ(total, fs::file_size(path));
    EXPECT_EQ(last_read, total);
    EXPECT_EQ(std::ftell(out), 0L) << "a bar for an input that opened at once";
    std::fclose(out);
    // A plain (not gzip) rawlog, which zlib's check does not read: the scan's own place.
    const std::string plain = d.str("plain.rawlog");
    {
        gzFile in = gzopen(path.c_str(), "rb");
        ASSERT_NE(in, nullptr);
        std::ofstream o(plain, std::ios::binary);
        std::vector<char> buf(1 << 16);
        for (int n; (n = gzread(in, buf.data(), static_cast<unsigned>(buf.size()))) > 0;)
            o.write(buf.data(), n);
        gzclose(in);
    }
    frames.clear();
    last_read = 0;
    std::uint64_t first_read = 0;
    ro.on_open = [&](std::size_t n, std::uint64_t r, std::uint64_t of) {
        if (frames.empty()) first_read = r;
        return count(n, r, of);
    };
    EXPECT_EQ(io::openRgbd(plain, ro)->size(), 6u);
    EXPECT_EQ(frames, (std::vector<std::size_t>{1, 2, 3, 4, 5, 6, 6}));
    EXPECT_TRUE(bytes_in_order);
    EXPECT_EQ(total, fs::file_size(plain));
    EXPECT_GT(total, fs::file_size(path));
    EXPECT_NEAR(double(first_read), total / 6.0, total / 60.0) << "one frame of six read";
    EXPECT_EQ(last_read, total);
    frames.clear();
    (void)io::openRgbd(kTum, ro);
    EXPECT_TRUE(frames.empty());
    // Asked to stop (Ctrl-C): the opening ends there, neither as damage nor as a reader.
    int calls = 0;
    ro.on_open = [&](std::size_t, std::uint64_t, std::uint64_t) { return ++calls < 3; };
    expectError<io::OpeningStopped>(
        [&] { (void)io::openRgbd(path, ro); },
        "six\\.rawlog: opening stopped after 3 RGB-D observations of it were found");
    // A bar's callback stops it when told to.
    io::OpenProgressBar bar(path, nullptr);
    ro.on_open = bar.callback([] { return true; });
    EXPECT_THROW((void)io::openRgbd(path, ro), io::OpeningStopped);
    // As the programs open their input: whole, and stopped by a recorded SIGTERM.
    EXPECT_EQ(io::openRgbdWithProgress(path, {}, nullptr)->size(), 6u);
    core::installStopHandler("test_io");
    core::clearStopSignal();
    ASSERT_EQ(std::raise(SIGTERM), 0);
    ASSERT_EQ(core::stopSignal(), SIGTERM);
    EXPECT_THROW((void)io::openRgbdWithProgress(path, {}, nullptr), io::OpeningStopped);
    core::clearStopSignal();
    std::signal(SIGTERM, SIG_DFL);
}

TEST(Rawlog, LaterObservationsNameTheFileAndObservation) {
    // The reader decodes only observation 0's images up front; a damaged later one must still
    // be named (file and observation), not surface as a bare MRPT or OpenCV message.
    TempDir d;
    io::RawlogWriterOptions wo;
    wo.external_images = true;
    const std::string path = d.str("ext.rawlog");
    writeShippedRawlog(path, 3, wo);
    // A file that is there but does not decode is found when its frame is read, and named: a
    // zero-byte one gave MRPT's banner alone ("==== MRPT exception ====").
    writeText(d.str("ext_Images/frame_1_rgb.png"), "");
    {
        io::RawlogReader r(path);
        EXPECT_TRUE(r.next());
        expectError([&] { (void)r.next(); },
                    R"(ext\.rawlog observation 1: external colour image '.*frame_1_rgb\.png' )"
                    R"(does not decode \(OpenCV: .*!buf\.empty\(\).*\)$)");
    }
    writeText(d.str("ext_Images/frame_1_rgb.png"), "not a png");
    {
        io::RawlogReader r(path);
        ASSERT_EQ(r.size(), 3u);
        EXPECT_TRUE(r.next());
        expectError([&] { (void)r.next(); },
                    R"(ext\.rawlog observation 1: external colour image '.*frame_1_rgb\.png' )"
                    R"(does not decode)");
        // The reader goes on after the bad observation, and counts it.
        const auto third = r.next();
        ASSERT_TRUE(third);
        EXPECT_EQ(third->index, 2u);
        EXPECT_FALSE(r.next());
    }
    // An external depth file cut short (a crash, a full disk): MRPT's reader fills the depth
    // image up to the cut and leaves the rest unset without a word.
    const std::string depth2 = d.str("ext_Images/frame_2_depth.bin");
    fs::resize_file(depth2, fs::file_size(depth2) / 2);
    {
        io::RawlogReader r(path);
        EXPECT_TRUE(r.next());
        expectError([&] { (void)r.next(); }, R"(ext\.rawlog observation 1: )");  // the PNG
        expectError([&] { (void)r.next(); },
                    R"(ext\.rawlog observation 2: external depth file '.*frame_2_depth\.bin' is )"
                    R"(damaged \(unexpected end of file\))");
    }
    // Cut early (MRPT's own read fails) or not gzip at all: named as well (MRPT's message
    // alone, "Cannot read requested number of bytes from stream", named no file).
    const std::string whole_depth = [&] {
        std::ifstream in(depth2, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    }();
    for (const auto& [content, says] : std::vector<std::pair<std::string, std::string>>{
             {whole_depth.substr(0, 100), "is damaged"}, {"junk\n", "does not decode"}}) {
        std::ofstream(depth2, std::ios::binary | std::ios::trunc) << content;
        io::RawlogReader r(path);
        EXPECT_TRUE(r.next());
        expectError([&] { (void)r.next(); }, R"(ext\.rawlog observation 1: )");  // the PNG
        expectError([&] { (void)r.next(); },
                    R"(ext\.rawlog observation 2: external depth file '.*frame_2_depth\.bin' )" +
                        says);
    }
    // A missing one is damage found at open: the frames before it stay usable.
    ASSERT_TRUE(fs::remove(d.str("ext_Images/frame_2_rgb.png")));
    expectError([&] { io::RawlogReader r(path); },
                R"(ext\.rawlog: observation 2: external file '.*frame_2_rgb\.png' not found )"
                R"(after 2 RGB-D observations)");
    io::ReaderOptions allow;
    allow.allow_damaged = true;
    io::RawlogReader partial(path, allow);
    EXPECT_EQ(partial.size(), 2u);

    // A colour image of four channels: named, not an OpenCV assertion from cvtColor.
    mrpt::obs::CObservation3DRangeScan o;
    o.hasIntensityImage = true;
    o.intensityImage =
        mrpt::img::CImage(cv::Mat(4, 4, CV_8UC4, cv::Scalar::all(9)), mrpt::img::DEEP_COPY);
    o.hasRangeImage = true;
    o.rangeImage_setSize(4, 4);
    expectError([&] { (void)io::frameFromObservation(o, "obs 7"); },
                R"(obs 7: colour image has 4 channels)");
}

TEST(Rawlog, ADamagedImageSizeIsAnErrorNotACrash) {
    // MRPT allocates the range image from the size fields before reading its pixels: rows
    // 0x7fffffff made its allocator return null and segfaulted in serializeFrom (Rawlog.cpp,
    // mrpt::aligned_malloc), and 100000 x 100000 made it zero 20 GB first.
    mrpt::obs::CObservation3DRangeScan o;
    o.hasRangeImage = true;
    o.rangeImage_setSize(6, 8);
    o.rangeImage.fill(1000);
    mrpt::io::CMemoryStream mem;
    mrpt::serialization::archiveFrom(mem) << o;
    const auto* bytes = static_cast<const char*>(mem.getRawBufferData());
    const std::string clean(bytes, bytes + mem.getTotalBytesCount());
    const std::uint32_t size[2] = {6, 8};
    const auto at = clean.find(std::string(reinterpret_cast<const char*>(size), sizeof size));
    ASSERT_NE(at, std::string::npos) << "the range image's rows and cols";
    TempDir d;
    for (const auto& [rows, cols] : std::vector<std::pair<std::uint32_t, std::uint32_t>>{
             {0x7fffffffu, 8u}, {100000u, 100000u}}) {
        std::string damaged = clean;
        const std::uint32_t bad[2] = {rows, cols};
        damaged.replace(at, sizeof bad, reinterpret_cast<const char*>(bad), sizeof bad);
        const std::string path = d.str("damaged.rawlog");
        std::ofstream(path, std::ios::binary) << damaged;
        expectError([&] { io::RawlogReader r(path); },
                    R"(damaged\.rawlog: cannot decode object 0 .*bytes could not be allocated)");
    }
}

TEST(Rawlog, ADamagedPointCountIsAnErrorNotACrash) {
    // A 3D scan's point lists are std::vectors that MRPT resizes to the count it reads: one
    // flipped byte (hasPoints3D) made that 1.4e9 points, and a list that could not be
    // allocated after one that could ended the program from the scan's destructor ("terminate
    // called", Rawlog.cpp's operator new). 80 million points (320 MB a list) is over the
    // reader's cap, so the first list is refused: the error names the block, where without
    // the cap 1.3 GB would be allocated and the stream would end early.
#ifdef __SANITIZE_ADDRESS__
    GTEST_SKIP() << "the AddressSanitizer build keeps its own operator new (Rawlog.cpp)";
#endif
    mrpt::obs::CObservation3DRangeScan o;
    o.hasRangeImage = true;
    o.rangeImage_setSize(2, 2);
    o.rangeImage.fill(1000);
    o.hasPoints3D = true;
    o.resizePoints3DVectors(3);
    o.points3D_x = {1.25f, 2.5f, 3.75f};
    mrpt::io::CMemoryStream mem;
    mrpt::serialization::archiveFrom(mem) << o;
    const auto* bytes = static_cast<const char*>(mem.getRawBufferData());
    std::string damaged(bytes, bytes + mem.getTotalBytesCount());
    const std::uint32_t count = 3;
    const float xs[3] = {1.25f, 2.5f, 3.75f};
    const std::string pattern = std::string(reinterpret_cast<const char*>(&count), sizeof count) +
                                std::string(reinterpret_cast<const char*>(xs), sizeof xs);
    const auto at = damaged.find(pattern);
    ASSERT_NE(at, std::string::npos) << "the point count and the x list";
    const std::uint32_t huge = 80'000'000;
    damaged.replace(at, sizeof huge, reinterpret_cast<const char*>(&huge), sizeof huge);
    TempDir d;
    const std::string path = d.str("points.rawlog");
    std::ofstream(path, std::ios::binary) << damaged;
    expectError([&] { io::RawlogReader r(path); },
                R"(points\.rawlog: cannot decode object 0 .*a block of 320000000 bytes could not )"
                R"(be allocated)");
}

TEST(Rawlog, ImpossibleCamerasAndDepthUnitsAreErrors) {
    // A focal length of 0, inf or 1e-300 made devslam-run's grid map loop forever; a depth
    // unit of 0 m read every depth as 0 without a word.
    io::TumReader tum(kTum);
    const core::Frame good = tum.read(0);
    TempDir d;
    const auto written = [&](const std::function<void(mrpt::obs::CObservation3DRangeScan&)>& f) {
        const std::string path = d.str("one.rawlog");
        {
            io::RawlogWriter w(path, {});
            w.write(good);
            w.close();
        }
        mrpt::io::CFileGZInputStream in(path);
        const auto o = std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(
            mrpt::serialization::archiveFrom(in).ReadObject());
        in.close();
        f(*o);
        mrpt::io::CFileGZOutputStream out(path);
        mrpt::serialization::archiveFrom(out) << *o;
        return path;
    };
    for (const double fx : {0.0, std::numeric_limits<double>::infinity(), 1e-300}) {
        const auto path = written([&](auto& o) { o.cameraParamsIntensity.fx(fx); });
        expectError([&] { io::RawlogReader r(path); },
                    R"(observation 0: colour camera: focal lengths fx .* must be in \[1, 1e5\])");
    }
    const auto depth_cam = written([](auto& o) { o.cameraParams.cy(-5); });
    expectError([&] { io::RawlogReader r(depth_cam); },
                R"(observation 0: depth camera: principal point \(.*, -5\) lies outside)");
    // A depth unit of 0, 1 m or 1e-9 m, a NaN or 1e10 m offset between the cameras, a k1 of
    // 1e6: each left frames without depth, without a word.
    for (const float unit : {0.0f, 1.0f, 1e-9f}) {
        const auto path = written([&](auto& o) { o.rangeUnits = unit; });
        expectError([&] { io::RawlogReader r(path); },
                    R"(observation 0: depth unit \(rangeUnits\) .* m: must be in \[1e-6, 0\.1\] m)");
    }
    for (const double x : {std::nan(""), 1e10}) {
        const auto path = written([&](auto& o) { o.relativePoseIntensityWRTDepth.x(x); });
        expectError([&] { io::RawlogReader r(path); },
                    R"(observation 0: the colour camera's pose relative to the depth camera )"
                    R"(\(relativePoseIntensityWRTDepth\) is .*: must be finite and within 1 m)");
    }
    const auto folded = written([](auto& o) { o.cameraParamsIntensity.dist[0] = 1e6; });
    expectError([&] { io::RawlogReader r(folded); },
                R"(observation 0: colour camera: a distortion coefficient is 1e\+06: must be in )"
                R"(\[-100, 100\])");
}

namespace {
// A 640x480 observation whose depth camera sees one point only, at depth pixel (600, 450): 2 m
// (range_is_depth) or 2 m of range along its ray. Both cameras at one place, fx = fy = 500,
// principal point in the middle; each with radial distortion k1 as given.
mrpt::obs::CObservation3DRangeScan onePointObservation(double depth_k1, double colour_k1,
                                                       bool range_is_depth = true) {
    mrpt::obs::CObservation3DRangeScan o;
    o.hasIntensityImage = true;
    o.intensityImage =
        mrpt::img::CImage(cv::Mat(480, 640, CV_8UC3, cv::Scalar(90, 90, 90)), mrpt::img::DEEP_COPY);
    o.hasRangeImage = true;
    o.rangeImage_setSize(480, 640);
    o.rangeImage.fill(0);
    o.rangeUnits = 0.0002f;
    o.rangeImage(450, 600) = 10000;  // 2 m
    o.range_is_depth = range_is_depth;
    for (auto* cam : {&o.cameraParams, &o.cameraParamsIntensity}) {
        cam->ncols = 640;
        cam->nrows = 480;
        cam->setIntrinsicParamsFromValues(500, 500, 319.5, 239.5);
    }
    o.cameraParams.setDistortionPlumbBob(depth_k1, 0, 0, 0, 0);
    o.cameraParamsIntensity.setDistortionPlumbBob(colour_k1, 0, 0, 0, 0);
    o.relativePoseIntensityWRTDepth = mrpt::poses::CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
    return o;
}

// The one pixel of `depth` that holds a depth, and that depth.
std::tuple<cv::Point, float> onlyDepth(const cv::Mat& depth) {
    EXPECT_EQ(cv::countNonZero(depth > 0), 1);
    cv::Point at;
    double hi = 0;
    cv::minMaxLoc(depth, nullptr, &hi, nullptr, &at);
    return {at, static_cast<float>(hi)};
}
}  // namespace

// A registered depth pixel lands where the colour lens puts its point, the raw pixel where
// the SLAM looks it up; with pinhole projections only, an OpenNI colour lens (k1 0.06, k2
// 0.04) moved depth up to ~20 px from its colour near the corners.
TEST(Rawlog, DepthIsRegisteredThroughBothLenses) {
    const double k1 = 0.1;
    const double x = (600 - 319.5) / 500, y = (450 - 239.5) / 500, r2 = x * x + y * y;
    {  // pinhole depth camera, distorted colour: pushed outwards by (1 + k1 r^2)
        const auto f = io::frameFromObservation(onePointObservation(0, k1), "o");
        const auto [at, z] = onlyDepth(f.depth);
        EXPECT_EQ(at.x, std::lround(319.5 + 500 * x * (1 + k1 * r2)));  // 614, not 600
        EXPECT_EQ(at.y, std::lround(239.5 + 500 * y * (1 + k1 * r2)));  // 460, not 450
        EXPECT_NEAR(z, 2.0, 1e-6);
        EXPECT_EQ(f.K.dist[0], k1);
    }
    {  // distorted depth camera (range along the ray), pinhole colour
        const auto f = io::frameFromObservation(onePointObservation(-k1, 0, false), "o");
        const auto [at, z] = onlyDepth(f.depth);
        // Its colour pixel's ray, distorted by the depth lens, is the depth pixel again.
        const double cx = (at.x - 319.5) / 500, cy = (at.y - 239.5) / 500;
        const double d = 1 - k1 * (cx * cx + cy * cy);
        EXPECT_NEAR(319.5 + 500 * cx * d, 600, 0.75);
        EXPECT_NEAR(239.5 + 500 * cy * d, 450, 0.75);
        // z from the range along the depth pixel's true ray (undistorted by fixed point)
        double ux = x, uy = y;
        for (int i = 0; i < 50; ++i) {
            const double f2 = 1 - k1 * (ux * ux + uy * uy);
            ux = x / f2;
            uy = y / f2;
        }
        EXPECT_NEAR(z, 2.0 / std::sqrt(1 + ux * ux + uy * uy), 1e-5);
    }
    {  // one lens for both, same place and pixels: registered as it is
        const auto f = io::frameFromObservation(onePointObservation(k1, k1), "o");
        const auto [at, z] = onlyDepth(f.depth);
        EXPECT_EQ(at, cv::Point(600, 450));
        EXPECT_NEAR(z, 2.0, 1e-6);
    }
}

// A calibration made for another resolution puts the principal point in the wrong pixels: a
// 640x480 one on a 320x240 image passed every check, its principal point in the corner.
TEST(Rawlog, ACalibrationForAnotherImageSizeIsRefused) {
    auto o = onePointObservation(0, 0);
    o.cameraParamsIntensity.ncols = 320;
    o.cameraParamsIntensity.nrows = 240;
    expectError([&] { (void)io::frameFromObservation(o, "x.rawlog observation 3"); },
                R"(x\.rawlog observation 3: colour camera: its calibration is for 320x240 but )"
                R"(the image is 640x480)");
    o = onePointObservation(0, 0);
    o.cameraParams.nrows = 240;
    expectError([&] { (void)io::frameFromObservation(o, "o"); },
                R"(o: depth camera: its calibration is for 640x240 but the image is 640x480)");
}

// Two RGB-D sensors in one rawlog, read without a sensor label, gave both cameras' frames
// as one camera's (interleaved), or, synchronised in one sensory frame, "duplicate timestamp"
// as if the file were damaged.
TEST(Rawlog, TwoSensorsWithoutALabelAreRefused) {
    TempDir d;
    auto obs = [](const char* label, double t) {
        auto o = mrpt::obs::CObservation3DRangeScan::Create(onePointObservation(0, 0));
        o->sensorLabel = label;
        o->timestamp = mrpt::Clock::fromDouble(t);
        return o;
    };
    const std::string interleaved = d.str("two.rawlog"), synced = d.str("synced.rawlog");
    {
        mrpt::io::CFileGZOutputStream out(interleaved);
        auto a = mrpt::serialization::archiveFrom(out);
        a << *obs("KINECT_L", 1.0) << *obs("KINECT_R", 1.01) << *obs("KINECT_L", 1.03);
    }
    {
        mrpt::io::CFileGZOutputStream out(synced);
        auto a = mrpt::serialization::archiveFrom(out);
        mrpt::obs::CSensoryFrame sf;
        sf.insert(obs("KINECT_L", 1.0));
        sf.insert(obs("KINECT_R", 1.0));
        a << mrpt::obs::CActionCollection() << sf;
    }
    for (const auto& path : {interleaved, synced}) {
        expectError([&] { io::RawlogReader r(path); },
                    R"(\.rawlog: RGB-D observations of more than one sensor \('KINECT_L' from )"
                    R"(observation 0, 'KINECT_R' at observation 1\): choose one with \[dataset\] )"
                    R"(sensor_label)");
        io::ReaderOptions o;
        o.allow_damaged = true;  // it is not damage
        expectError([&] { io::RawlogReader r(path, o); }, "more than one sensor");
        o.sensor_label = "KINECT_R";
        io::RawlogReader r(path, o);
        EXPECT_EQ(r.size(), 1u);
    }
    io::ReaderOptions o;
    o.sensor_label = "KINECT_L";
    EXPECT_EQ(io::RawlogReader(interleaved, o).size(), 2u);
}

// Two rawlogs of different cameras joined (cat a b > c): the frames after the join were read
// with their own camera but the reader (and devslam-run, devslam-convert) gave the first
// one's. The camera that changes is refused where it changes, as damage: the frames before
// are the intact part.
TEST(Rawlog, ACameraThatChangesMidStreamIsRefusedWhereItChanges) {
    TempDir d;
    const auto obs = [](double t, double fx, int w, int h, bool calibrated) {
        auto o = onePointObservation(0, 0);
        const cv::Mat small(h, w, CV_8UC3, cv::Scalar(90, 90, 90));
        if (w != 640) {
            o.intensityImage = mrpt::img::CImage(small, mrpt::img::DEEP_COPY);
            o.rangeImage_setSize(h, w);
            o.rangeImage.fill(0);
            o.rangeImage(h / 2, w / 2) = 10000;
        }
        for (auto* cam : {&o.cameraParams, &o.cameraParamsIntensity}) {
            cam->ncols = calibrated ? w : 0;
            cam->nrows = calibrated ? h : 0;
            // (uncalibrated: the same numbers whatever the size)
            cam->setIntrinsicParamsFromValues(fx, fx, calibrated ? 0.5 * w - 0.5 : 319.5,
                                              calibrated ? 0.5 * h - 0.5 : 239.5);
        }
        o.timestamp = mrpt::Clock::fromDouble(t);
        return o;
    };
    const auto write = [&](const std::string& name, const std::vector<double>& fx,
                           const std::vector<int>& w, bool calibrated) {
        const std::string path = d.str(name);
        mrpt::io::CFileGZOutputStream out(path);
        auto a = mrpt::serialization::archiveFrom(out);
        for (std::size_t k = 0; k < fx.size(); ++k)
            a << obs(1.0 + 0.1 * double(k), fx[k], w[k], w[k] * 3 / 4, calibrated);
        return path;
    };
    // Another focal length, and another size with its calibration: found by the scan at open.
    for (const auto& path : {write("fx.rawlog", {500, 500, 400}, {640, 640, 640}, true),
                             write("size.rawlog", {500, 500, 50}, {640, 640, 64}, true)}) {
        expectError([&] { io::RawlogReader r(path); },
                    R"(\.rawlog: observation 2: colour camera .* differs from observation 0's )"
                    R"(640x480 fx 500 fy 500 cx 319\.5 cy 239\.5: a rawlog of one camera is )"
                    R"(expected after 2 RGB-D observations)");
        for (const auto& f : intactFrames(path, 2)) EXPECT_EQ(f.K.fx, 500.0);
    }
    // Uncalibrated sizes (ncols 0: the image's size is taken): the same calibration, another
    // image size, found when the frame is read; the frames before it were read.
    const std::string raw = write("uncal.rawlog", {500, 500}, {640, 320}, false);
    io::RawlogReader r(raw);
    ASSERT_TRUE(r.next().has_value());
    expectError([&] { (void)r.next(); },
                R"(uncal\.rawlog observation 1: its colour image is 320x240, observation 0's )"
                R"(640x480: a rawlog of one camera is expected)");
}

// Intrinsics given for a rawlog are for its images' size, as a TUM folder's are.
TEST(Rawlog, GivenIntrinsicsOfAnotherSizeAreRefused) {
    TempDir d;
    const std::string path = d.str("one.rawlog");
    {
        mrpt::io::CFileGZOutputStream out(path);
        mrpt::serialization::archiveFrom(out) << onePointObservation(0, 0);
    }
    io::ReaderOptions o;
    o.intrinsics = core::CameraIntrinsics::fromPreset("freiburg1").scaled(0.5);
    expectError([&] { io::RawlogReader r(path, o); },
                R"(one\.rawlog: the given camera intrinsics are for 320x240 but observation 0's )"
                R"(colour image is 640x480)");
    o.intrinsics = core::CameraIntrinsics::fromPreset("freiburg1");
    io::RawlogReader r(path, o);
    const auto f = r.next();
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->K.fx, o.intrinsics->fx);
}

TEST(Rawlog, ReadsMrptsOwnOpenNiObservation) {
    // One real OpenNI2 observation: depth in mm, not registered to colour.
    ASSERT_TRUE(fs::exists(kMrptRgbd)) << "installed by Debian's mrpt-common";
    io::RawlogReader r(kMrptRgbd);
    EXPECT_EQ(r.size(), 1u);
    const auto f = r.next();
    ASSERT_TRUE(f.has_value());
    EXPECT_NEAR(f->timestamp, 1462879443.617188, 1e-5);
    EXPECT_EQ(f->depth_scale, 1000.0);
    EXPECT_EQ(f->depth.size(), f->bgr.size());
    EXPECT_NEAR(f->K.fx, 521.17923, 1e-4);  // the colour camera's intrinsics
    double lo = 0, hi = 0;
    cv::minMaxLoc(f->depth, &lo, &hi, nullptr, nullptr, f->depth > 0);
    EXPECT_GT(lo, 1.5);  // the raw depth spans 1.624 .. 2.560 m along the depth camera's axis
    EXPECT_LT(hi, 2.6);
    EXPECT_GT(cv::countNonZero(f->depth > 0), 200000);  // of 273225 valid depth pixels
    EXPECT_FALSE(r.next().has_value());

    // Written as a TUM folder, its depth is in TUM's 5000 units per metre: read back, it is
    // the same (it was written in millimetres and read as 0.2 mm units, 5x too near).
    TempDir d;
    {
        io::TumWriter w(d.str("tum"), "test");
        w.write(*f);
        w.close();
    }
    auto back = io::openRgbd(d.str("tum"), {});
    const auto g = back->next();
    ASSERT_TRUE(g.has_value());
    EXPECT_EQ(g->depth_scale, 5000.0);
    // (Its depth is reprojected into the colour camera: not whole millimetres, so within the
    // rounding to TUM's 0.2 mm units.)
    EXPECT_LE(cv::norm(g->depth, f->depth, cv::NORM_INF), 0.5 / 5000 + 1e-7);
}

TEST(Rawlog, RejectsFramesThatCannotBeWritten) {
    TempDir d;
    io::RawlogWriter w(d.str("x.rawlog"), {});
    core::Frame f;
    f.bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar(1, 2, 3));
    f.depth = cv::Mat(100, 100, CV_32FC1, cv::Scalar(1.0f));
    EXPECT_THROW(w.write(f), std::runtime_error);
    io::RawlogWriterOptions bad;
    bad.compression = 11;
    EXPECT_THROW(io::RawlogWriter(d.str("y.rawlog"), bad), std::invalid_argument);
}

// 16-bit depth at 5000 units per metre ends at 13.1 m: a farther reading was saturated to a
// wall at 13.1 m in a rawlog (a TUM folder already refused it). Both refuse it now.
TEST(Rawlog, DepthBeyondSixteenBitsIsRefusedNotClipped) {
    TempDir d;
    core::Frame f = io::TumReader(kTum).read(0);
    f.depth.at<float>(10, 20) = 15.0f;
    io::RawlogWriter w(d.str("far.rawlog"), {});
    expectError([&] { w.write(f); },
                "depth 15.0+ m does not fit a rawlog's range image \\(16 bits at 5000 per "
                "metre: at most 13.1 m\\)");
    io::TumWriter t(d.str("far_tum"));
    expectError([&] { t.write(f); }, "frame 0: depth 15.0+ m does not fit a TUM depth PNG");
    f.depth.at<float>(10, 20) = 13.1f;  // the farthest depth that fits
    ASSERT_NO_THROW(w.write(f));
    w.close();
    io::RawlogReader r(d.str("far.rawlog"));
    const auto back = r.next();
    ASSERT_TRUE(back.has_value());
    EXPECT_NEAR(back->depth.at<float>(10, 20), 13.1f, 2e-4f) << "clipped?";
}

// A full disk at the end: a frame of one colour fits zlib's buffers, which go out (and fail)
// only at the close. MRPT's gz stream ignored that, and the cut rawlog passed for written.
TEST(Rawlog, AFullDiskAtTheCloseIsAnError) {
    if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
    core::Frame f = io::TumReader(kTum).read(0);
    f.bgr = cv::Mat(f.bgr.size(), CV_8UC3, cv::Scalar(0, 0, 0));
    f.depth = cv::Mat(f.depth.size(), CV_32FC1, cv::Scalar(1.0f));
    io::RawlogWriter w("/dev/full", {});
    w.write(f);
    expectError([&] { w.close(); }, "error writing rawlog '/dev/full'");
    w.close();  // closed once: nothing more to report
}

// A file-size limit (RLIMIT_FSIZE, with SIGXFSZ ignored) for a scope: each file is cut at
// the limit as on a disk that fills there, and writes past it fail (EFBIG).
class FileSizeLimit {
  public:
    explicit FileSizeLimit(rlim_t bytes) : old_signal_(std::signal(SIGXFSZ, SIG_IGN)) {
        getrlimit(RLIMIT_FSIZE, &old_);
        rlimit l = old_;
        l.rlim_cur = bytes;
        EXPECT_EQ(setrlimit(RLIMIT_FSIZE, &l), 0);
    }
    ~FileSizeLimit() {
        setrlimit(RLIMIT_FSIZE, &old_);
        std::signal(SIGXFSZ, old_signal_);
    }
    FileSizeLimit(const FileSizeLimit&) = delete;
    FileSizeLimit& operator=(const FileSizeLimit&) = delete;

  private:
    rlimit old_{};
    void (*old_signal_)(int);
};

// A disk that fills during an image file's last buffer: OpenCV's PNG encoder does not check
// fclose(), nor MRPT's gz stream gzclose(), so the cut file passed for written. Each writer
// writes the frame once to learn the file's size, then again with the limit one byte below.
TEST(Writers, AnImageFileCutAtItsEndIsAnError) {
    const core::Frame f = io::TumReader(kTum).read(0);
    TempDir d;
    {
        io::TumWriter ok(d.str("ok"));
        ok.write(f);
    }
    std::uintmax_t rgb_size = 0;
    for (const auto& e : fs::directory_iterator(d.str("ok/rgb")))
        rgb_size = fs::file_size(e.path());
    ASSERT_GT(rgb_size, 1000u);
    {
        io::TumWriter cut(d.str("cut"));
        FileSizeLimit limit(rgb_size - 1);
        expectError([&] { cut.write(f); },
                    "cannot write '.*cut/rgb/[0-9.]+\\.png': File too large");
    }
    // Whole or not at all: no cut picture, no .part left.
    EXPECT_TRUE(fs::is_empty(d.str("cut/rgb")));

    // A rawlog with external images: a black colour image (a small PNG), then the depth.
    core::Frame b = f;
    b.bgr = cv::Mat(f.bgr.size(), CV_8UC3, cv::Scalar(0, 0, 0));
    io::RawlogWriterOptions wo;
    wo.external_images = true;
    {
        io::RawlogWriter ok(d.str("ok.rawlog"), wo);
        ok.write(b);
        ok.close();
    }
    const auto depth_size = fs::file_size(d.str("ok_Images/frame_0_depth.bin"));
    ASSERT_GT(depth_size, fs::file_size(d.str("ok_Images/frame_0_rgb.png")));
    {
        io::RawlogWriter cut(d.str("cut.rawlog"), wo);
        FileSizeLimit limit(depth_size - 1);
        expectError([&] { cut.write(b); },
                    "cannot write '.*cut_Images/frame_0_depth\\.bin': .*\\(disk full\\?\\)");
    }
    {
        // And the colour image, when the limit cuts it.
        io::RawlogWriter cut(d.str("cut2.rawlog"), wo);
        FileSizeLimit limit(fs::file_size(d.str("ok_Images/frame_0_rgb.png")) - 1);
        expectError([&] { cut.write(b); },
                    "cannot write '.*cut2_Images/frame_0_rgb\\.png': File too large");
    }
    EXPECT_FALSE(fs::exists(d.str("cut2_Images/frame_0_rgb.png")));
}

// A text file given as a rawlog got MRPT's "Expecting 0x00 00 00 while parsing old streaming
// header" alone: the error now says what the file starts with.
TEST(Rawlog, ATextFileIsNamedForWhatItStartsWith) {
    TempDir d;
    const std::string path = d.str("notes.rawlog");
    std::ofstream(path) << "hello\tworld\nsecond line\n";
    try {
        io::RawlogReader r(path);
        ADD_FAILURE() << "a text file opened as a rawlog";
    } catch (const std::runtime_error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("notes.rawlog: cannot decode object 0 at byte 0 of the uncompressed "
                         "stream: not a rawlog? It starts with 'hello?world?second line?' where a "
                         "rawlog starts with an MRPT class name"),
                  std::string::npos)
            << m;
    }
}

// Binary garbage read as an object's class name was echoed to the terminal in the error.
TEST(Rawlog, AGarbageClassNameIsNotEchoed) {
    TempDir d;
    const std::string path = d.str("junk.rawlog");
    {
        std::ofstream out(path, std::ios::binary);
        out << char(0x80 | 100);  // MRPT's header: a class name of 100 bytes follows
        for (int c = 130; c < 230; ++c) out << char(c);
        out << std::string(200, '\x01');
    }
    try {
        io::RawlogReader r(path);
        ADD_FAILURE() << "garbage opened as a rawlog";
    } catch (const std::runtime_error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("junk.rawlog: cannot decode object 0 at byte 0"), std::string::npos) << m;
        for (const char c : m)
            EXPECT_TRUE(c >= 0x20 && c <= 0x7e) << "byte " << int(static_cast<unsigned char>(c));
        const auto a = m.find("class '"), b = m.find("' which");
        ASSERT_NE(a, std::string::npos) << m;
        ASSERT_NE(b, std::string::npos) << m;
        EXPECT_LE(b - a - 7, 60u) << m;
        EXPECT_NE(m.find("class '?????"), std::string::npos) << m;
    }
}

// Frames are named and listed by their stamps: one not after the previous frame's lost a
// frame (two entries, one image pair) or wrote an unsorted rgb.txt. Refused as TumReader
// refuses such lists, by the rawlog reader (the frames before it are the intact part) and by
// the TUM writer (nothing of that frame written).
TEST(Rawlog, StampsThatDoNotIncreaseAreRefused) {
    TempDir d;
    copyTumSubset(d.str("s"), 4);
    io::TumReader tum(d.str("s"));
    std::vector<core::Frame> frames;
    while (auto f = tum.next()) frames.push_back(*f);
    ASSERT_EQ(frames.size(), 4u);
    const double t0 = frames[0].timestamp;
    for (const auto& [name, t2, kind] : {std::tuple{"dup.rawlog", t0 + 0.1, "duplicate"},
                                         std::tuple{"back.rawlog", t0 - 1.0, "unsorted"}}) {
        const std::string path = d.str(name);
        {
            io::RawlogWriter w(path, {});
            const double stamps[] = {t0, t0 + 0.1, t2, t0 + 0.3};
            for (std::size_t k = 0; k < 4; ++k) {
                core::Frame f = frames[k];
                f.timestamp = stamps[k];
                w.write(f);
            }
        }
        char a[32], b[32];
        std::snprintf(a, sizeof a, "%.6f", t2);
        std::snprintf(b, sizeof b, "%.6f", t0 + 0.1);
        const std::string msg = std::string(kind) + " timestamp " + a +
                                " \\(previous observation 1 at " + b +
                                "\\) after 2 RGB-D observations";
        expectError([&] { io::RawlogReader r(path); },
                    std::string(name).replace(std::string(name).find('.'), 1, "\\.") +
                        ": observation 2: " + msg);
        (void)intactFrames(path, 2);
    }

    // The TUM writer: a duplicate (also one within the microsecond the names keep) or an
    // earlier stamp names both frames; the frames before it stay listed.
    int folder = 0;
    for (const double t1 : {t0, t0 + 4e-7, t0 - 0.5}) {
        const std::string out = d.str("tum" + std::to_string(folder++));
        io::TumWriter w(out, "test");
        core::Frame f = frames[0];
        f.index = 7;
        f.depth_timestamp.reset();
        w.write(f);
        f = frames[1];
        f.index = 8;
        f.timestamp = t1;
        f.depth_timestamp.reset();
        char a[32];
        std::snprintf(a, sizeof a, "%.6f", t0);
        expectError([&] { w.write(f); }, std::string("frame 8: ") +
                                             (t1 < t0 - 0.1 ? "unsorted" : "duplicate") +
                                             " timestamp .* \\(previous frame 7 at " + a + "\\)");
        w.close();
        EXPECT_EQ(io::readTumList(out + "/rgb.txt").size(), 1u);
        EXPECT_EQ(std::distance(fs::directory_iterator(out + "/rgb"), fs::directory_iterator{}), 1);
    }
}

TEST(VideoReader, ReadsVtestAsFixedCameraFramesWithAPlaneOfDepth) {
    const std::string vtest = "/usr/share/doc/opencv-doc/examples/data/vtest.avi";  // opencv-doc
    ASSERT_TRUE(fs::exists(vtest)) << "installed by Debian's opencv-doc (./devslam.sh setup)";
    io::VideoReader video(vtest, {3.0, 0.0});
    ASSERT_EQ(video.size(), std::optional<std::size_t>(795));
    EXPECT_EQ(video.intrinsics().width, 768);
    EXPECT_EQ(video.intrinsics().height, 576);
    EXPECT_DOUBLE_EQ(video.intrinsics().fx, 768.0);
    std::size_t n = 0;
    while (auto f = video.next()) {
        EXPECT_EQ(f->index, n);
        EXPECT_DOUBLE_EQ(f->timestamp, static_cast<double>(n) / 10.0);  // a 10 Hz file
        if (n == 0 || n == 794) {
            core::validateFrame(*f, f->rgb_source);
            double lo = 0, hi = 0;
            cv::minMaxLoc(f->depth, &lo, &hi);
            EXPECT_EQ(lo, 3.0);
            EXPECT_EQ(hi, 3.0);
        }
        ++n;
    }
    EXPECT_EQ(n, 795u);
    EXPECT_EQ(video.damage(), "");
}

// A video cut short decodes what is there, and says that the rest is missing once read.
TEST(VideoReader, AVideoCutShortSaysHowManyOfItsFramesDecoded) {
    const std::string vtest = "/usr/share/doc/opencv-doc/examples/data/vtest.avi";  // opencv-doc
    ASSERT_TRUE(fs::exists(vtest)) << "installed by Debian's opencv-doc (./devslam.sh setup)";
    TempDir tmp;
    {
        std::ifstream in(vtest, std::ios::binary);
        std::string head(800000, '\0');  // a tenth of the file
        in.read(head.data(), static_cast<std::streamsize>(head.size()));
        std::ofstream(tmp.str("cut.avi"), std::ios::binary) << head;
    }
    io::VideoReader video(tmp.str("cut.avi"), {});
    ASSERT_EQ(video.size(), std::optional<std::size_t>(795));  // the header's count
    std::size_t n = 0;
    while (video.next()) ++n;
    EXPECT_GT(n, 10u);
    EXPECT_LT(n, 200u);
    EXPECT_EQ(video.damage(), tmp.str("cut.avi") + ": " + std::to_string(n) +
                                  " of the 795 frames the container states decoded; the file "
                                  "may be cut short or damaged after frame " +
                                  std::to_string(n - 1));
}

TEST(VideoReader, BadFilesAndOptionsNameTheFile) {
    TempDir tmp;
    expectError([&] { io::VideoReader v(tmp.str("missing.avi"), {}); }, R"(missing\.avi: no such)");
    { std::ofstream(tmp.str("text.avi")) << "not a video\n"; }
    expectError([&] { io::VideoReader v(tmp.str("text.avi"), {}); }, R"(text\.avi)");
    // A text file named .txt: FFmpeg decodes it (its tty demuxer draws the text as frames).
    expectError([&] { io::VideoReader v(kTum + "/rgb.txt", {}); },
                R"(rgb\.txt: a text file, not a video \(FFmpeg would draw its text as frames\))");
    expectError<std::invalid_argument>(
        [&] {
            io::VideoReader v(kTum + "/rgb.txt", {0.0, 0.0});
        },
        "plane_depth");
    expectError<std::invalid_argument>(
        [&] {
            io::VideoReader v(kTum + "/rgb.txt", {2.0, -1.0});
        },
        "focal");
    // openRgbd does not take videos for RGB-D input, and says where they can go.
    expectError([&] { (void)io::openRgbd(tmp.str("text.avi")); },
                R"(text\.avi: a video has no depth)");
}
