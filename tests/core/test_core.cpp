#include <devslam/core/Association.h>
#include <devslam/core/Camera.h>
#include <devslam/core/Config.h>
#include <devslam/core/Frame.h>
#include <devslam/core/GzFile.h>
#include <devslam/core/Interrupt.h>
#include <devslam/core/Parse.h>
#include <devslam/core/Picture.h>
#include <devslam/core/Pose.h>
#include <devslam/core/Results.h>
#include <devslam/core/Stats.h>

#include <gtest/gtest.h>

#include <zlib.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include "ConfigRoundTrip.h"
#include "Scratch.h"

#include <atomic>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <thread>
#include <tuple>
#include <typeinfo>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <iostream>

using namespace devslam::core;

TEST(Camera, PresetsMatchTumCalibration) {
    const auto K = CameraIntrinsics::fromPreset("freiburg1");
    EXPECT_DOUBLE_EQ(K.fx, 517.3);
    EXPECT_DOUBLE_EQ(K.cy, 255.3);
    EXPECT_DOUBLE_EQ(CameraIntrinsics::fromPreset("fr3").fx, 535.4);
}

TEST(Camera, UnknownPresetListsKnownOnes) {
    try {
        (void)CameraIntrinsics::fromPreset("kinect9");
        FAIL() << "expected an exception";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("kinect9"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("freiburg2"), std::string::npos);
    }
}

TEST(Camera, BackprojectProjectRoundTrip) {
    const auto K = CameraIntrinsics::fromPreset("freiburg3");
    const Eigen::Vector3d p = backproject(100.25, 400.5, 2.5, K);
    EXPECT_DOUBLE_EQ(p.z(), 2.5);
    const auto uv = project(p, K);
    ASSERT_TRUE(uv.has_value());
    EXPECT_NEAR(uv->x(), 100.25, 1e-9);
    EXPECT_NEAR(uv->y(), 400.5, 1e-9);
    EXPECT_FALSE(project(Eigen::Vector3d(0, 0, -1), K).has_value());
}

TEST(Camera, ScaledKeepsPixelCentres) {
    // A point seen at pixel (u, v) of the full image lies at ((u + 0.5) s - 0.5, ...) of the
    // image resized by s: the corners of the image scale, the centres of pixels do not.
    const auto K = CameraIntrinsics::fromPreset("freiburg3");
    const auto H = K.scaled(0.5);
    EXPECT_EQ(H.width, 320);
    EXPECT_EQ(H.height, 240);
    const Eigen::Vector3d p(0.3, -0.2, 2.0);
    const auto full = project(p, K), half = project(p, H);
    ASSERT_TRUE(full && half);
    EXPECT_NEAR(half->x(), (full->x() + 0.5) * 0.5 - 0.5, 1e-9);
    EXPECT_NEAR(half->y(), (full->y() + 0.5) * 0.5 - 0.5, 1e-9);
    const auto back = H.scaled(2.0);  // and back
    EXPECT_NEAR(back.cx, K.cx, 1e-12);
    EXPECT_NEAR(back.cy, K.cy, 1e-12);
    EXPECT_EQ(back.fx, K.fx);
    EXPECT_EQ(back.width, K.width);
}

TEST(Camera, ConfigRoundTripAndErrors) {
    auto K = CameraIntrinsics::fromPreset("freiburg2");
    mrpt::config::CConfigFileMemory mem;
    K.saveToConfig(mem, "camera");
    EXPECT_EQ(CameraIntrinsics::fromConfig(mem, "camera"), K);

    mrpt::config::CConfigFileMemory typo("[camera]\npreset = freiburg1\nfxx = 3\n");
    EXPECT_THROW((void)CameraIntrinsics::fromConfig(typo, "camera"), std::invalid_argument);
    mrpt::config::CConfigFileMemory missing("[camera]\nfx = 500\nfy = 500\ncx = 320\n");
    try {
        (void)CameraIntrinsics::fromConfig(missing, "camera");
        ADD_FAILURE() << "no error for a missing cy";
    } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()), "[camera] cy: required key is missing");
    }
    mrpt::config::CConfigFileMemory bad("[camera]\npreset = fr1\ncx = 900\n");
    EXPECT_THROW((void)CameraIntrinsics::fromConfig(bad, "camera"), std::invalid_argument);
    // A focal length that passed "> 0" but made the SLAM's grid map loop forever.
    mrpt::config::CConfigFileMemory tiny("[camera]\npreset = fr1\nfx = 1e-300\n");
    try {
        (void)CameraIntrinsics::fromConfig(tiny, "camera");
        ADD_FAILURE() << "fx = 1e-300 accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()), "[camera] fx/fy: must be in [1, 1e5] px");
    }
    // problem()'s bound on the distortion, which the file's reader lacked: a TUM folder's
    // camera.ini with k1 = 1e9 lost every frame after the first, naming no file.
    mrpt::config::CConfigFileMemory wild("[camera]\npreset = fr1\ndist = [1e9 0 0 0 0]\n");
    try {
        (void)CameraIntrinsics::fromConfig(wild, "camera");
        ADD_FAILURE() << "k1 = 1e9 accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()).rfind("[camera] dist: each coefficient must be in "
                                              "[-100, 100]",
                                              0),
                  0u)
            << e.what();
    }
    mrpt::config::CConfigFileMemory fisheye("[camera]\npreset = fr1\ndist = [-100 0 0 0 100]\n");
    EXPECT_EQ(CameraIntrinsics::fromConfig(fisheye, "camera").dist[4], 100);
    EXPECT_EQ(CameraIntrinsics::fromPreset("fr3").problem(), "");
    auto B = CameraIntrinsics::fromPreset("fr1");
    B.fy = std::numeric_limits<double>::infinity();
    EXPECT_EQ(B.problem(), "focal lengths fx 517.3, fy inf px: must be in [1, 1e5]");
    B = CameraIntrinsics::fromPreset("fr1");
    B.cx = 640;
    EXPECT_EQ(B.problem(), "principal point (640, 255.3) lies outside the 640x480 image");
    B = CameraIntrinsics::fromPreset("fr1");
    B.dist[2] = std::nan("");
    EXPECT_EQ(B.problem(), "a distortion coefficient is nan: must be in [-100, 100]");
}

// Every key of [camera], from a preset (saved as its values): read back, at full precision.
TEST(Camera, EveryKeyRoundTrips) {
    devslam::test::expectEveryKeyRoundTrips(
        [](const devslam::test::Ini& in, devslam::test::Ini& out) {
            CameraIntrinsics::fromConfig(in, "camera").saveToConfig(out, "camera");
        },
        {{}, {}, {{"camera", "preset"}}}, devslam::test::Ini("[camera]\npreset = freiburg1\n"));
}

TEST(Config, WrittenRealsReadBackExactly) {
    mrpt::config::CConfigFileMemory mem;
    for (const double v : {0.000123456789, 123456.789, 1.0 / 3.0, -2.5e-9, 1e300, 0.1, 3.0}) {
        writeKey(mem, "s", "v", v);
        EXPECT_EQ(readDouble(mem, "s", "v", 0), v) << mem.read_string("s", "v", "");
    }
    writeKey(mem, "s", "v", 0.1);
    EXPECT_EQ(mem.read_string("s", "v", ""), "0.1");  // no more digits than it needs
    writeKey(mem, "s", "list", std::vector<double>{0.2624, -1.0 / 7.0, 0});
    const auto back = parseNumberList(mem.read_string("s", "list", ""), "list");
    EXPECT_EQ(back, (std::vector<double>{0.2624, -1.0 / 7.0, 0}));
    writeKey(mem, "s", "n", 12);
    writeKey(mem, "s", "b", true);
    EXPECT_EQ(mem.read_string("s", "n", ""), "12");
    EXPECT_EQ(mem.read_string("s", "b", ""), "true");
}

TEST(Config, UnknownKeyIsNamed) {
    mrpt::config::CConfigFileMemory mem("[a]\nx = 1\ny = 2\n");
    EXPECT_EQ(unknownKeys(mem, "a", {"x"}), std::vector<std::string>{"y"});
    try {
        requireKnownKeys(mem, "a", {"x"}, "test.ini");
        FAIL();
    } catch (const std::invalid_argument& e) {
        EXPECT_STREQ(e.what(), "test.ini [a]: unknown key 'y' (known: x)");
    }
    EXPECT_THROW((void)loadIni("/nonexistent/file.ini"), std::runtime_error);
}

/// The message of the std::invalid_argument `f` throws ("" when it throws none).
template <class F>
std::string invalidArgument(F&& f) {
    try {
        f();
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "";
}

TEST(Config, FilterIniFollowsRunFilterConfigWithOverrides) {
    // The shipped SLAM INI names dynamic_filter.ini and overrides its detection interval.
    const std::string slam_ini = std::string(DEVSLAM_SOURCE_DIR) + "/config_ini/slam_tum_fr1.ini";
    const auto f = loadFilterIni(*loadIni(slam_ini), slam_ini);
    EXPECT_TRUE(f->sectionExists("detector"));
    EXPECT_EQ(f->read_int("dynamic_filter", "detect_every", 0), 3);
    // Without [run] filter_config the INI is its own filter INI; overrides still apply.
    const std::string dir = devslam::test::scratchPath("devslam_core").string();
    std::filesystem::create_directories(dir);
    const std::string own = dir + "/own.ini";
    std::ofstream(own) << "[run]\nfilter_overrides = dynamic_filter.mask_margin=3\n"
                          "[dynamic_filter]\nmask_margin = 10\n";
    EXPECT_EQ(loadFilterIni(*loadIni(own), own)->read_int("dynamic_filter", "mask_margin", 0), 3);
    // A malformed override names the file and the item; a missing filter INI names its path.
    const std::string bad = dir + "/bad.ini";
    std::ofstream(bad) << "[run]\nfilter_overrides = detect_every=3\n";
    try {
        (void)loadFilterIni(*loadIni(bad), bad);
        FAIL();
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("'detect_every=3'"), std::string::npos) << e.what();
    }
    // A mistyped section was written into a section nothing reads, and a key set twice kept
    // the last: both are refused, naming the item.
    const auto refusal = [&](const std::string& overrides) {
        std::ofstream(bad) << "[run]\nfilter_overrides = " << overrides << "\n";
        try {
            (void)loadFilterIni(*loadIni(bad), bad);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_EQ(refusal("dynamic_filtr.detect_every=3"),
              bad +
                  " [run] filter_overrides item 'dynamic_filtr.detect_every=3': section "
                  "'dynamic_filtr' is not one of the filter's (detector, dynamic_filter)");
    EXPECT_EQ(refusal("dynamic_filter.mask_margin=3 dynamic_filter.Mask_Margin=4"),
              bad +
                  " [run] filter_overrides item 'dynamic_filter.Mask_Margin=4': "
                  "[dynamic_filter] Mask_Margin is set twice (also "
                  "'dynamic_filter.mask_margin=3')");
    const std::string missing = dir + "/missing.ini";
    std::ofstream(missing) << "[run]\nfilter_config = nowhere.ini\n";
    try {
        (void)loadFilterIni(*loadIni(missing), missing);
        FAIL();
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find(missing + " [run] filter_config: no such file '" +
                                             dir + "/nowhere.ini'"),
                  std::string::npos)
            << e.what();
    }
    // One that is there but not a file (a folder, /dev/null) is not "no such file".
    std::ofstream(missing) << "[run]\nfilter_config = .\n";
    try {
        (void)loadFilterIni(*loadIni(missing), missing);
        FAIL();
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find(missing + " [run] filter_config: not a regular file '"),
                  std::string::npos)
            << e.what();
    }
    // A filter INI without the filter's sections (an empty file, a slip of the name) ran the
    // filter on its defaults.
    std::ofstream(dir + "/empty.ini") << "# nothing yet\n";
    std::ofstream(missing) << "[run]\nfilter_config = empty.ini\n";
    try {
        (void)loadFilterIni(*loadIni(missing), missing);
        FAIL() << "a filter INI without [detector] or [dynamic_filter] was taken";
    } catch (const std::invalid_argument& e) {
        EXPECT_STREQ(e.what(), (missing + " [run] filter_config: '" + dir +
                                "/empty.ini' has no [detector] or [dynamic_filter] section")
                                   .c_str());
    }
    std::ofstream(dir + "/empty.ini") << "[detector]\n";  // one of them is enough
    EXPECT_NO_THROW((void)loadFilterIni(*loadIni(missing), missing));
    // What devslam-bench, devslam-overlay and devslam-filter-bench read: a SLAM INI that lost
    // its filter_config line passed, because its filter_overrides make the section they set,
    // and the filter ran on the code's defaults.
    std::ofstream(own) << "[run]\nfilter_overrides = dynamic_filter.detect_every=3\n";
    EXPECT_EQ(invalidArgument([&] { (void)loadFilterConfig(own); }),
              own + ": no [detector] or [dynamic_filter] section, and no [run] filter_config "
                    "naming an INI that has them ([run] filter_overrides only changes keys of "
                    "one)");
    std::ofstream(own) << "[run]\nfilter_config = empty.ini\n"
                          "filter_overrides = dynamic_filter.detect_every=3\n";
    std::string source;
    EXPECT_EQ(loadFilterConfig(own, &source)->read_int("dynamic_filter", "detect_every", 0), 3);
    EXPECT_EQ(source, dir + "/empty.ini with " + own + " [run] filter_overrides");
    std::filesystem::remove_all(dir);
}

TEST(Parse, NumbersAreReadInFullOrRejected) {
    EXPECT_DOUBLE_EQ(parseNumber("0.5", "x"), 0.5);
    EXPECT_DOUBLE_EQ(parseNumber(" -1e-3\t", "x"), -1e-3);
    EXPECT_DOUBLE_EQ(parseNumber("3.000000e+01", "x"), 30.0);  // MRPT's $eval{} output
    EXPECT_EQ(invalidArgument([] { (void)parseNumber("0.5m", "[a] k"); }),
              "[a] k: expected a number, got '0.5m'");
    // strtod reads C's hexadecimal ("0x10" = 16): no INI reader takes it for a number.
    for (const char* bad : {"", "  ", "abc", "1,5", "nan", "inf", "1e999", "2 3", "0x10", "0x1p-5",
                            "0X1P3", "-1e999"})
        EXPECT_NE(invalidArgument([&] { (void)parseNumber(bad, "x"); }), "") << bad;
    // An underflow is the subnormal or zero it rounds to, as Python's float() reads it:
    // strtod flags it ERANGE like an overflow, and it was refused.
    EXPECT_DOUBLE_EQ(parseNumber("1e-320", "x"), 1e-320);
    EXPECT_GT(parseNumber("1e-320", "x"), 0.0);
    EXPECT_EQ(parseNumber("-1e-400", "x"), 0.0);
    EXPECT_EQ(parseNumber("2.2250738585072014e-308", "x"), 2.2250738585072014e-308);
}

TEST(Parse, AnOptionsValueIsNotTheNextOption) {
    const std::vector<std::string> args{"app", "--from", "-1,2", "--method", "--png", "x.png"};
    std::size_t i = 1;
    EXPECT_EQ(optionValue(args, i), "-1,2");  // one dash: a value
    EXPECT_EQ(i, 2u);
    i = 3;
    EXPECT_EQ(invalidArgument([&] { (void)optionValue(args, i); }), "--method needs a value");
    i = 5;
    EXPECT_EQ(invalidArgument([&] { (void)optionValue(args, i); }), "x.png needs a value");
}

TEST(Parse, AnOptionGivenTwiceIsRefused) {
    // A parser kept the last of two --out without a word: the first run's folder was not
    // written, and nothing said so.
    EXPECT_NO_THROW(refuseRepeatedOptions(
        std::vector<std::string>{"--set", "a.b=1", "--set", "a.c=2", "--out", "x", "-1,2"},
        {"--set"}));
    EXPECT_EQ(invalidArgument([] {
                  refuseRepeatedOptions(std::vector<std::string>{"--out", "x", "--quiet", "--out",
                                                                 "y"});
              }),
              "--out is given twice (give it once: the last one would replace the first)");
    EXPECT_EQ(invalidArgument([] {
                  refuseRepeatedOptions(std::vector<std::string>{"-o", "x", "--out", "y"}, {},
                                        {{"-o", "--out"}});
              }).substr(0, 20),
              "--out is given twice");
    // Flags too; --help and one-dash words (values, negative numbers) are not counted.
    EXPECT_NE(invalidArgument([] {
                  refuseRepeatedOptions(std::vector<std::string>{"--quiet", "--quiet"});
              }),
              "");
    EXPECT_NO_THROW(refuseRepeatedOptions(
        std::vector<std::string>{"--help", "--help", "-1", "-1", "pos", "pos"}));
    // main's argv: argv[0], the program, is not an option.
    char prog[] = "--out", a1[] = "--out", a2[] = "x";
    char* argv[] = {prog, a1, a2};
    EXPECT_NO_THROW(refuseRepeatedOptions(3, argv));
}

TEST(Parse, NumberListsNameTheBadToken) {
    EXPECT_EQ(parseNumberList("[1 2.5, -3]", "x"), (std::vector<double>{1, 2.5, -3}));
    EXPECT_TRUE(parseNumberList("  ", "x").empty());
    EXPECT_EQ(invalidArgument([] { (void)parseNumberList("1 2m", "[a] k"); }),
              "[a] k: '2m' is not a number");
    for (const char* t : {"nan", "-inf", "1e400"})
        EXPECT_EQ(invalidArgument([&] { (void)parseNumberList(std::string("1 ") + t, "[a] k"); }),
                  std::string("[a] k: '") + t + "' is not a finite number");
    EXPECT_EQ(invalidArgument([] { (void)parseNumberList("1 2", "[a] k", 3); }),
              "[a] k: expected 3 numbers, got 2");
    // A ']' lost in an edit was read as if it were there.
    EXPECT_EQ(parseNumberList(" [1 2] ", "x"), (std::vector<double>{1, 2}));
    for (const char* t : {"[2.4 1.6 2.4 4.4", "1 2]", "[1 2] [3 4]", "1 [2 3]", "]1 2["})
        EXPECT_EQ(invalidArgument([&] { (void)parseNumberList(t, "[a] k"); }),
                  std::string("[a] k: '") + t + "' has unmatched brackets (write [a b c] or a b c)")
            << t;
}

TEST(Parse, ClippedQuotesALongTextInPart) {
    using devslam::core::clipped;
    EXPECT_EQ(clipped("  short  "), "  short  ");  // blanks may be what is wrong: kept
    EXPECT_EQ(clipped(std::string(80, 'a')), std::string(80, 'a'));
    EXPECT_EQ(clipped(std::string(81, 'a')), std::string(80, 'a') + "... (81 bytes)");
    // Never half a character: "\u00e9" is two bytes, and the 80th byte is the first of one.
    std::string accents = std::string(79, 'a');
    for (int i = 0; i < 10; i++) accents += "\u00e9";
    EXPECT_EQ(clipped(accents), std::string(79, 'a') + "... (99 bytes)");
}

TEST(Parse, ExtensionsInAnyCase) {
    EXPECT_TRUE(endsWithNoCase("a/b.PNG", ".png"));
    EXPECT_TRUE(endsWithNoCase("b.png", ".png"));
    EXPECT_FALSE(endsWithNoCase("b.jpgx", ".png"));
    EXPECT_FALSE(endsWithNoCase("png", ".png"));
    EXPECT_TRUE(endsWith("a/b.rawlog", ".rawlog"));
    EXPECT_TRUE(endsWith(".rawlog", ".rawlog"));
    EXPECT_FALSE(endsWith("b.RAWLOG", ".rawlog"));
    EXPECT_FALSE(endsWith("rawlog", ".rawlog"));
}

// An output that is an input, under another spelling or through a link, is told apart from
// a file of its own.
// Where making a folder starts: the folder, else its nearest existing parent; "" (the parent
// of a bare file name, devslam-synth --rawlog x.rawlog) is the working folder, where
// fs::absolute threw.
TEST(Results, NearestExistingStartsAtTheWorkingFolderForNoFolder) {
    namespace fs = std::filesystem;
    EXPECT_EQ(nearestExisting(""), fs::current_path().lexically_normal());
    EXPECT_EQ(nearestExisting("."), fs::current_path().lexically_normal());
    const fs::path tmp = fs::temp_directory_path();
    EXPECT_EQ(nearestExisting((tmp / "devslam_no_such/a/b").string()), tmp.lexically_normal());
}

TEST(Results, SameFileSeesThroughSpellingsAndLinks) {
    devslam::test::TempDir d("devslam_core_");
    namespace fs = std::filesystem;
    std::ofstream(d.str("a.txt")) << "a";
    std::ofstream(d.str("b.txt")) << "a";
    fs::create_symlink("a.txt", d.str("link.txt"));
    EXPECT_TRUE(devslam::core::sameFile(d.str("a.txt"), d.str("a.txt")));
    EXPECT_TRUE(devslam::core::sameFile(d.str("a.txt"), d.str("./a.txt")));
    EXPECT_TRUE(devslam::core::sameFile(d.str("a.txt"), d.str("link.txt")));
    EXPECT_FALSE(devslam::core::sameFile(d.str("a.txt"), d.str("b.txt")));
    EXPECT_FALSE(devslam::core::sameFile(d.str("a.txt"), d.str("new.txt")));  // not there yet
    EXPECT_FALSE(devslam::core::sameFile(d.str("gone.txt"), d.str("a.txt")));
}

TEST(Parse, IntegersAreWholeAndInRange) {
    EXPECT_EQ(parseInteger("42", "x"), 42);
    EXPECT_EQ(parseInteger("+7", "x"), 7);
    EXPECT_EQ(parseInteger("1e3", "x"), 1000);  // atoi reads 1
    EXPECT_EQ(parseInteger("3.000000e+01", "x"), 30);
    EXPECT_EQ(parseInteger("18446744073709551", "x"), 18446744073709551LL);  // past 2^53
    EXPECT_EQ(parseInteger("-5", "x", -5, 5), -5);
    EXPECT_EQ(invalidArgument([] { (void)parseInteger("7x", "--frames", 1); }),
              "--frames: expected an integer, got '7x'");
    EXPECT_EQ(invalidArgument([] { (void)parseInteger("-5", "--frames", 0); }),
              "--frames: expected an integer >= 0, got '-5'");
    EXPECT_EQ(invalidArgument([] { (void)parseInteger("9", "--k", 1, 8); }),
              "--k: expected an integer in [1, 8], got '9'");
    EXPECT_EQ(invalidArgument(
                  [] { (void)parseInteger("9", "--k", std::numeric_limits<long long>::min(), 8); }),
              "--k: expected an integer <= 8, got '9'");
    for (const char* bad :
         {"", "2.5", "1e-3", "abc", "99999999999999999999", "1e30", "0.1e1x", "0x10", "0x1p4"})
        EXPECT_NE(invalidArgument([&] { (void)parseInteger(bad, "x"); }), "") << bad;
}

TEST(Parse, BooleansAreSpelledOut) {
    for (const char* t : {"true", "TRUE", "Yes", "on", "1", " true "})
        EXPECT_TRUE(parseBool(t, "x")) << t;
    for (const char* f : {"false", "False", "no", "OFF", "0"}) EXPECT_FALSE(parseBool(f, "x")) << f;
    EXPECT_EQ(invalidArgument([] { (void)parseBool("ture", "[local_ba] enabled"); }),
              "[local_ba] enabled: expected true or false, got 'ture'");
    EXPECT_NE(invalidArgument([] { (void)parseBool("", "x"); }), "");
}

TEST(Config, OverrideListsKeepBracketedValuesWhole) {
    EXPECT_EQ(overrideItems("  a.b=1\tc.d=2  "), (std::vector<std::string>{"a.b=1", "c.d=2"}));
    EXPECT_EQ(overrideItems("p.path=[3.5 2.1]  p.speed=1 q.v=[1 [2 3]]"),
              (std::vector<std::string>{"p.path=[3.5 2.1]", "p.speed=1", "q.v=[1 [2 3]]"}));
    EXPECT_TRUE(overrideItems(" ").empty());
    mrpt::config::CConfigFileMemory mem;
    applyOverrides(mem, overrideItems("p.path=[3.5 2.1]"));
    EXPECT_EQ(mem.read_string("p", "path", ""), "[3.5 2.1]");
    // Blanks around the names and the value, as an INI line has them (a --set in quotes).
    applyOverrides(mem, {" orb . n_features = 300 "});
    std::vector<std::string> keys;
    mem.getAllKeys("orb", keys);
    EXPECT_EQ(keys, (std::vector<std::string>{"n_features"}));
    EXPECT_EQ(mem.read_string("orb", "n_features", ""), "300");
    for (const std::string bad : {" .k=1", "s. =1", "s.k", ".=", "s=k.1"})
        EXPECT_EQ(invalidArgument([&] { applyOverrides(mem, {bad}, "--set"); }),
                  "--set '" + bad + "': expected SECTION.KEY=VALUE")
            << bad;
    const std::string msg =
        invalidArgument([] { (void)overrideItems("p.path=[3.5 2.1", "x.ini set"); });
    EXPECT_EQ(msg, "x.ini set 'p.path=[3.5 2.1': a '[' is not closed");
}

TEST(Config, SectionsComeInTheFilesOrder) {
    const std::string path = devslam::test::scratchPath("devslam_order").string() + ".ini";
    std::ofstream(path) << "[zeta]\na = 1\n  [alpha]\nb = 2\n[mid]\n";
    const auto cfg = loadIni(path);
    std::vector<std::string> sorted;
    cfg->getAllSections(sorted);
    ASSERT_EQ(sorted.size(), 3u);  // MRPT's own list is sorted, hence this helper
    EXPECT_EQ(sectionsInFileOrder(*cfg, path), (std::vector<std::string>{"zeta", "alpha", "mid"}));
    // A file that cannot be read again still gives every section, in MRPT's order.
    EXPECT_EQ(sectionsInFileOrder(*cfg, path + ".gone"), sorted);
    const std::string keys = devslam::test::scratchPath("devslam_keys").string() + ".ini";
    std::ofstream(keys) << "[t]\nzz = 1\n  b=2   // comment = x\na = 3\n[u]\na = 0\n";
    EXPECT_EQ(keysInFileOrder(*loadIni(keys), keys, "t"),
              (std::vector<std::string>{"zz", "b", "a"}));
    EXPECT_EQ(keysInFileOrder(*loadIni(keys), keys + ".gone", "t"),
              (std::vector<std::string>{"a", "b", "zz"}));
    std::filesystem::remove(path);
    std::filesystem::remove(keys);
}

// MRPT keeps the last of a repeated key (names in any letter case) and merges a repeated
// section into the first, silently: both are refused with the two lines.
TEST(Config, RepeatedKeysAndSectionsAreRefused) {
    const std::string path = devslam::test::scratchPath("devslam_repeat").string() + ".ini";
    const auto error = [&](const std::string& text) {
        std::ofstream(path) << text;
        try {
            (void)loadIni(path);
        } catch (const std::exception& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_EQ(error("[goal]\nx = 3\ny = 2\nx = 5\n"),
              path + " line 4: [goal] x repeated (first at line 2)");
    EXPECT_EQ(error("[goal]\nx = 3\n  X=5 // again\n"),
              path + " line 3: [goal] X repeated (first at line 2)");
    EXPECT_EQ(error("[a]\nk = 1\n[b]\n[A]\nj = 2\n"),
              path + " line 4: section [A] repeated (first at line 1)");
    EXPECT_EQ(error("[a]\nk = 1\n[ a ]\nj = 2\n"),  // MRPT trims the name
              path + " line 3: section [ a ] repeated (first at line 1)");
    // MRPT's @define: keys are compared as MRPT reads them.
    EXPECT_EQ(error("@define P PTG0\n[a]\n${P}_K = 1\n@define P PTG2\n${P}_K = -1\n"), "");
    EXPECT_EQ(error("@define P PTG0\n[a]\n${P}_K = 1\nPTG0_K = 2\n"),
              path + " line 4: [a] PTG0_K repeated (first at line 3)");
    // A '\\' followed by blanks ends its line: MRPT joins only at a '\\' right at the end.
    EXPECT_EQ(error("[a]\nk = 1 \\  \nk = 2\n"),
              path + " line 3: [a] k repeated (first at line 2)");
    // Lines MRPT would misread or drop without a word.
    EXPECT_EQ(error("[navigator\nk = 1\n"), path + " line 1: '[navigator' has no ']'");
    EXPECT_EQ(error("[a]\nk = 1\nspeed 3\n"),
              path + " line 3: 'speed 3' is neither a [section] nor a key = value");
    // A junk line is quoted in part: a 500 kB one was quoted whole.
    EXPECT_EQ(error("[a]\nk = 1\n" + std::string(100000, 'x') + "\n"),
              path + " line 3: '" + std::string(80, 'x') +
                  "... (100000 bytes)' is neither a [section] nor a key = value");
    // MRPT 2.5 knows @define alone and skips any other directive: "@include" read nothing.
    EXPECT_EQ(error("@include other.ini\n[a]\nk = 1\n"),
              path +
                  " line 1: '@include' is no directive MRPT knows (only @define): the line "
                  "would be ignored");
    EXPECT_EQ(error("[orb] junk\nk = 1\n"),
              path + " line 1: '[orb] junk': text after the section's ']'");
    EXPECT_EQ(error("[orb] # the features\n[b] // more\n[c] ; and\nk = 1\n"), "");
    // A key before any section, or under "[]", was named without its line.
    EXPECT_EQ(error("# a room\nsize = 1\n[room]\n"),
              path + " line 2: key 'size' before the first [section]");
    EXPECT_EQ(error("[a]\nk = 1\n [ ] \nj = 2\n"), path + " line 3: '[ ]' names no section");
    // A comment ending in '\' takes the next line into it: a key there is lost (here MRPT
    // read the default instead of n = 20); a comment there is not.
    EXPECT_EQ(error("[orb]\n# see C:\\docs\\\nn = 20\n"),
              path +
                  " line 2: a comment ends in '\\', so MRPT reads line 3 ('n = 20') as part "
                  "of it");
    EXPECT_EQ(error("[orb]\n#   a command \\\n#       --more \\\n\nn = 20\n"), "");
    // A define whose value holds its own name is used once (the check ran for ever).
    EXPECT_EQ(error("@define A ${A}\n[a]\n${A} = 4\n"), "");
    // A variable no @define gives: MRPT's message, with the file (it named none).
    EXPECT_EQ(error("[a]\nk = 1\nr = ${REF_DIST}\n"),
              path + ": Line 3: Unknown variable `${REF_DIST}`");
    // Not repeats: one key in two sections, comments, a value continued on the next lines.
    EXPECT_EQ(error("[a]\nk = 1\n# k = 2\n; k = 3\n// k = 4\n[b]\nk = 5\nf = \\\n"
                    "  var k := 1; \\\n  k = 2\n"),
              "");
    EXPECT_EQ(loadIni(path)->read_string("b", "k", ""), "5");
    std::filesystem::remove(path);
    EXPECT_EQ(error(""), "");  // an empty INI is no error
    std::filesystem::remove(path);
    std::filesystem::create_directories(path);
    EXPECT_EQ(error("x"), "INI file '" + path + "' is a folder");
    std::filesystem::remove_all(path);
    // A file without end (or a rawlog given for the INI) was read until memory ran out.
    try {
        (void)loadIni("/dev/zero");
        FAIL() << "/dev/zero was read as an INI";
    } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "INI file '/dev/zero' is over 16 MiB: not an INI file");
    }
}

// A NUL byte in a line hid the key before it from requireKnownKeys (fuzz: "bogus_key\0 = 1"
// appended to a SLAM INI ran with rc 0): refused, naming the file and the line.
TEST(Config, NulByteIsRefusedWithItsLine) {
    devslam::test::TempDir d("devslam_core_");
    const std::string path = d.str("nul.ini");
    // loadIni's message for an INI holding `text`.
    const auto errorOf = [&](const std::string& text) -> std::string {
        std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
        try {
            (void)loadIni(path);
        } catch (const std::invalid_argument& e) {
            return e.what();
        }
        return "no error";
    };
    EXPECT_EQ(errorOf(std::string("[a]\nk = 1\nbogus_key\0 = 1\n", 25)),
              path + " line 3: a NUL byte (a binary file, or a damaged INI)");
    // Another control byte (a binary file given for the INI): its line and code, not the raw
    // bytes as an unknown "key".
    EXPECT_EQ(errorOf("[a]\nk = 1\n\x0f\x8b\x03 = 1\n"),
              path + " line 3: control byte 0x0f (a binary file, or a damaged INI)");
}

// A UTF-8 byte-order mark (Windows editors write one) made line 1 "neither a [section] nor
// a key = value".
TEST(Config, AByteOrderMarkIsNotPartOfTheFirstLine) {
    devslam::test::TempDir d("devslam_core_");
    const std::string path = d.str("bom.ini");
    std::ofstream(path, std::ios::binary) << "\xEF\xBB\xBF[run]\r\nmode = none\r\n";
    const auto ini = loadIni(path);
    EXPECT_EQ(ini->read_string("run", "mode", "", true), "none");
}

TEST(Config, UnknownSectionsAndKeysBeforeAnySectionAreErrors) {
    const std::vector<std::string> known{"room", "box_*"};
    mrpt::config::CConfigFileMemory ok("[room]\nsize = 1\n[box_desk]\nx = 2\n[box_]\n");
    EXPECT_NO_THROW(requireKnownSections(ok, known, "r.ini"));
    mrpt::config::CConfigFileMemory typo("[room]\nsize = 1\n[bx_desk]\nx = 2\n");
    EXPECT_EQ(invalidArgument([&] { requireKnownSections(typo, known, "r.ini"); }),
              "r.ini: unknown section [bx_desk] (known: room, box_*)");
    EXPECT_EQ(invalidArgument([&] { requireKnownSections(typo, known); }),
              "unknown section [bx_desk] (known: room, box_*)");  // for a caller that adds the file
    // a prefix is only a prefix when it ends in '*'
    mrpt::config::CConfigFileMemory longer("[rooms]\nsize = 1\n");
    EXPECT_EQ(invalidArgument([&] { requireKnownSections(longer, known, "r.ini"); }),
              "r.ini: unknown section [rooms] (known: room, box_*)");
    mrpt::config::CConfigFileMemory early("size = 1\n[room]\nx = 2\n");
    EXPECT_EQ(invalidArgument([&] { requireKnownSections(early, known, "r.ini"); }),
              "r.ini: key 'size' before the first section");
    // comments and blank lines before the first section are no keys
    mrpt::config::CConfigFileMemory comments("# a room\n\n// and more\n[room]\nx = 2\n");
    EXPECT_NO_THROW(requireKnownSections(comments, known, "r.ini"));
}

TEST(Config, StrictReadsNameSectionKeyAndValue) {
    mrpt::config::CConfigFileMemory mem(
        "[a]\nn = 12 // a trailing comment is stripped\nbig = 1e3\nx = 0.25\non = yes\n"
        "typo_int = 12x\ntypo_num = 0.5.1\ntypo_bool = ture\nempty =\nseed = 12345678901\n"
        "neg_seed = -1\nhuge = 3000000000\n");
    EXPECT_EQ(readInt(mem, "a", "n", 0), 12);
    EXPECT_EQ(readInt(mem, "a", "big", 0), 1000);  // MRPT's read_int gives 1
    EXPECT_DOUBLE_EQ(readDouble(mem, "a", "x", 0.0), 0.25);
    EXPECT_TRUE(readBool(mem, "a", "on", false));
    EXPECT_EQ(readUint64(mem, "a", "seed", 0), 12345678901ULL);
    // Absent keys give the default, or an error naming them when required.
    EXPECT_EQ(readInt(mem, "a", "absent", 7), 7);
    EXPECT_DOUBLE_EQ(readDouble(mem, "b", "absent", 1.5), 1.5);
    EXPECT_FALSE(readBool(mem, "a", "absent", false));
    EXPECT_EQ(invalidArgument([&] { (void)readDouble(mem, "a", "absent", 0.0, true); }),
              "[a] absent: required key is missing");
    // Malformed values name section, key and text (MRPT reads 12, 0.5 and false).
    EXPECT_EQ(invalidArgument([&] { (void)readInt(mem, "a", "typo_int", 0); }),
              "[a] typo_int: expected an integer, got '12x'");
    EXPECT_EQ(invalidArgument([&] { (void)readDouble(mem, "a", "typo_num", 0.0); }),
              "[a] typo_num: expected a number, got '0.5.1'");
    EXPECT_EQ(invalidArgument([&] { (void)readBool(mem, "a", "typo_bool", true); }),
              "[a] typo_bool: expected true or false, got 'ture'");
    for (const auto& [key, read] : std::vector<std::pair<std::string, std::function<void()>>>{
             {"empty", [&] { (void)readInt(mem, "a", "empty", 3); }},
             {"neg_seed", [&] { (void)readUint64(mem, "a", "neg_seed", 0); }},
             {"huge", [&] { (void)readInt(mem, "a", "huge", 0); }}}) {  // huge: > int
        const std::string e = invalidArgument(read);
        EXPECT_EQ(e.rfind("[a] " + key + ": ", 0), 0u) << e;
    }
    EXPECT_EQ(invalidArgument([&] { (void)readInt(mem, "a", "x", 0); }),
              "[a] x: expected an integer, got '0.25'");
}

TEST(Config, NamingSourcePrefixesFieldOnlyErrors) {
    EXPECT_EQ(namingSource("f.ini", [] { return 5; }), 5);
    mrpt::config::CConfigFileMemory mem("[a]\nn = 3y\n");
    EXPECT_EQ(invalidArgument(
                  [&] { (void)namingSource("f.ini", [&] { return readInt(mem, "a", "n", 0); }); }),
              "f.ini [a] n: expected an integer, got '3y'");
    // A message that already names its source, and other exception types, pass unchanged.
    EXPECT_EQ(invalidArgument([] {
                  namingSource("f.ini", [] { throw std::invalid_argument("room.ini [room]: x"); });
              }),
              "room.ini [room]: x");
    try {  // (an invalid_argument is a logic_error: the exact type is checked)
        namingSource("f.ini", [] { throw std::logic_error("[a] bug"); });
        ADD_FAILURE() << "no error";
    } catch (const std::logic_error& e) {
        EXPECT_TRUE(typeid(e) == typeid(std::logic_error)) << typeid(e).name();
        EXPECT_EQ(std::string(e.what()), "[a] bug");
    }
    // A file a key names that does not load (a runtime_error) is named with the INI too.
    try {
        namingSource("f.ini", [] { throw std::runtime_error("[a] weights: file not found"); });
        ADD_FAILURE() << "no error";
    } catch (const std::invalid_argument&) {
        ADD_FAILURE() << "became an invalid_argument";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), "f.ini [a] weights: file not found");
    }
    try {
        namingSource("f.ini", [] { throw std::runtime_error("disk: io"); });
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), "disk: io");
    }
}

// A section is replaced in place, others are kept; broken markers stop it before it writes
// (appending would make the next run replace every section between the two BEGINs).
TEST(Results, SectionsAreReplacedInPlaceAndBrokenMarkersRefused) {
    const std::string path = devslam::test::scratchPath("devslam_results").string() + ".md";
    std::filesystem::remove(path);
    const auto read = [&] {
        std::ifstream in(path);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    replaceResultsSection(path, "a", "one");
    replaceResultsSection(path, "b", "two\n");
    replaceResultsSection(path, "a", "three");
    const std::string text = read();
    EXPECT_NE(text.find("<!-- BEGIN a -->\nthree\n<!-- END a -->"), std::string::npos) << text;
    EXPECT_EQ(text.find("one"), std::string::npos) << text;
    EXPECT_LT(text.find("BEGIN a"), text.find("BEGIN b")) << text;  // in place, b kept after it
    EXPECT_NE(text.find("<!-- BEGIN b -->\ntwo\n<!-- END b -->"), std::string::npos) << text;
    EXPECT_THROW(replaceResultsSection(path, "A b", "x"), std::invalid_argument);
    // a's END removed by hand: refused, the file as it was.
    std::string broken = text;
    broken.erase(broken.find("<!-- END a -->"), std::string("<!-- END a -->").size());
    std::ofstream(path, std::ios::trunc) << broken;
    try {
        replaceResultsSection(path, "a", "four");
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find(path + "': section 'a' needs '<!-- BEGIN a -->' "
                                                    "and, after it, '<!-- END a -->'"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_EQ(read(), broken);
    // The same checks, before a command's work, writing nothing.
    EXPECT_THROW(checkResultsSection(path, "a"), std::runtime_error);
    EXPECT_NO_THROW(checkResultsSection(path, "b"));
    EXPECT_THROW(checkResultsSection(path, "B c"), std::invalid_argument);
    EXPECT_THROW(checkResultsSection(path + "_none/R.md", "b"), std::runtime_error);
    // Not a Markdown file (a bench's own INI named by mistake): refused, nothing written.
    const std::string ini = path + ".ini";
    std::ofstream(ini) << "[bench]\n";
    try {
        replaceResultsSection(ini, "b", "x");
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("results file '" + ini +
                                             "' is not a Markdown file (.md); nothing was written"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_THROW(checkResultsSection(ini, "b"), std::runtime_error);
    {
        std::ifstream in(ini);
        EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "[bench]\n");
    }
    std::filesystem::remove(ini);
    // A folder no file can be made in (as root too): refused before the work, not after it.
    try {
        checkResultsSection("/proc/R.md", "b");
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("results file '/proc/R.md': cannot write in '/proc'"),
                  std::string::npos)
            << e.what();
    }
    const auto folder = std::filesystem::path(path).parent_path();
    for (const auto& f : std::filesystem::directory_iterator(folder))
        EXPECT_EQ(f.path().filename().string().rfind(".devslam-write-probe", 0), std::string::npos)
            << "the probe is removed";
    EXPECT_THROW(checkResultsSection(std::filesystem::path(path).parent_path().string(), "b"),
                 std::runtime_error);
    EXPECT_EQ(read(), broken);
    // A binary file named .md got a section appended; a section there twice had only its
    // first replaced, the second keeping old figures.
    for (const std::string& bad :
         {std::string("# R\n\x01\x02garbage\n"),
          std::string("<!-- BEGIN b -->\nold\n<!-- END b -->\n<!-- BEGIN b -->\nolder\n"
                      "<!-- END b -->\n")}) {
        std::ofstream(path, std::ios::trunc) << bad;
        try {
            replaceResultsSection(path, "b", "new");
            ADD_FAILURE() << "no error for " << bad;
        } catch (const std::runtime_error& e) {
            const std::string m = e.what();
            EXPECT_TRUE(m.find("holds control bytes: not a Markdown text file") !=
                            std::string::npos ||
                        m.find("section 'b' is there twice; remove one") != std::string::npos)
                << m;
        }
        EXPECT_EQ(read(), bad);
    }
    std::filesystem::remove(path);
}

// A results file that is there but cannot be read was taken for a new one: the section was
// written alone, and the file's other sections were lost. Root reads any file, so the write
// runs in a child as nobody when the test runs as root.
TEST(Results, AFileThatCannotBeReadIsNotWrittenOver) {
    devslam::test::TempDir d("devslam_");
    const std::string path = d.str("RESULTS.md");
    const std::string text =
        "# R\n<!-- BEGIN a -->\nold\n<!-- END a -->\n<!-- BEGIN b -->\nkept\n<!-- END b -->\n";
    std::ofstream(path) << text;
    namespace fs = std::filesystem;
    fs::permissions(d.str(), fs::perms::all);  // the child may write beside it
    fs::permissions(path,
                    fs::perms::owner_write | fs::perms::group_write | fs::perms::others_write);
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        if (geteuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0)) _exit(3);
        try {
            replaceResultsSection(path, "a", "new");
            _exit(0);
        } catch (const std::runtime_error& e) {
            _exit(std::string(e.what()).find(path + "' is there but cannot be read") !=
                          std::string::npos
                      ? 1
                      : 2);
        } catch (...) {
            _exit(4);
        }
    }
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 1) << "0: written over; 2: another error; 3: no setuid";
    fs::permissions(path, fs::perms::owner_read | fs::perms::owner_write);
    std::ifstream in(path);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), text);
}

// Two commands regenerating their sections at once (say devslam-bench and devslam-nav-bench,
// each at its end) both read the file, change their section and write it back: without a
// lock one's section is lost, or both write the same .part. Here four writers, each with its
// own section, 25 times over: every section holds its writer's last text.
TEST(Results, WritersAtOnceLoseNoSection) {
    const std::string path = devslam::test::scratchPath("devslam_results_race").string() + ".md";
    std::filesystem::remove(path);
    constexpr int kWriters = 4, kRounds = 25;
    std::vector<std::thread> writers;
    std::atomic<int> failed{0};
    for (int w = 0; w < kWriters; ++w)
        writers.emplace_back([&path, &failed, w] {
            for (int r = 0; r < kRounds; ++r) try {
                    replaceResultsSection(
                        path, "s" + std::to_string(w),
                        "writer " + std::to_string(w) + " round " + std::to_string(r));
                } catch (const std::exception&) {  // e.g. another writer renamed the .part
                    ++failed;
                }
        });
    for (auto& t : writers) t.join();
    EXPECT_EQ(failed.load(), 0);
    std::ifstream in(path);
    const std::string text(std::istreambuf_iterator<char>(in), {});
    for (int w = 0; w < kWriters; ++w) {
        const std::string s = std::to_string(w);
        EXPECT_NE(text.find("<!-- BEGIN s" + s + " -->\nwriter " + s + " round " +
                            std::to_string(kRounds - 1) + "\n<!-- END s" + s + " -->"),
                  std::string::npos)
            << text;
    }
    EXPECT_FALSE(std::filesystem::exists(path + ".part"));
    std::filesystem::remove(path);
}

// A writer reaching the results file through a link (here one whose file is not made yet,
// in another folder) takes its turn on the folder the file is written in, as a writer naming
// the file itself does: while that folder is locked, the writer through the link waits.
TEST(Results, WriterThroughALinkWaitsForTheFoldersLock) {
    namespace fs = std::filesystem;
    const auto dir = devslam::test::scratchPath("results_lock_link");
    fs::remove_all(dir);
    fs::create_directories(dir / "a");
    fs::create_directories(dir / "b");
    fs::create_symlink("../b/RESULTS.md", dir / "a" / "RESULTS.md");
    const int fd = ::open((dir / "b").c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::flock(fd, LOCK_EX), 0);
    std::atomic<bool> done{false};
    std::thread writer([&] {
        replaceResultsSection((dir / "a" / "RESULTS.md").string(), "s", "through the link");
        done = true;
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_FALSE(done.load());  // it waits for b/, the folder it writes in
    EXPECT_FALSE(fs::exists(dir / "b" / "RESULTS.md"));
    ::close(fd);  // releases the lock
    writer.join();
    EXPECT_TRUE(done.load());
    EXPECT_TRUE(fs::is_symlink(dir / "a" / "RESULTS.md"));
    std::ifstream in(dir / "b" / "RESULTS.md");
    const std::string text(std::istreambuf_iterator<char>(in), {});
    EXPECT_NE(text.find("through the link"), std::string::npos) << text;
    fs::remove_all(dir);
}

// A file is replaced whole or not at all; its hash tells a change of content.
TEST(Results, FilesAreWrittenWholeAndHashedByContent) {
    const auto dir = devslam::test::scratchPath("results_whole");
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const std::string f = (dir / "a.txt").string();
    devslam::core::writeFileWhole(f, "one\n");
    devslam::core::writeFileWhole(f, "two\n");
    std::ifstream in(f);
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, "two");
    EXPECT_FALSE(std::filesystem::exists(f + ".part"));
    EXPECT_THROW(devslam::core::writeFileWhole((dir / "no/such/b.txt").string(), "x"),
                 std::runtime_error);
    // A write that fails leaves the old file as it was (here the .part cannot be made).
    std::filesystem::create_directories(f + ".part");
    EXPECT_THROW(devslam::core::writeFileWhole(f, "three\n"), std::runtime_error);
    std::filesystem::remove_all(f + ".part");
    std::ifstream again(f);
    std::getline(again, line);
    EXPECT_EQ(line, "two");
    const std::string h = devslam::core::fileHash(f);
    EXPECT_EQ(h.size(), 16u);
    EXPECT_EQ(devslam::core::fileHash(f), h);
    devslam::core::writeFileWhole(f, "twO\n");
    EXPECT_NE(devslam::core::fileHash(f), h);
    // A device is written into, not renamed over (as root, a .part renamed over /dev/null
    // would have replaced it): /dev/null stays a device, /dev/full is a named write error.
    devslam::core::writeFileWhole("/dev/null", "gone\n");
    EXPECT_FALSE(std::filesystem::is_regular_file("/dev/null"));
    EXPECT_FALSE(std::filesystem::exists("/dev/null.part"));
    try {
        devslam::core::writeFileWhole("/dev/full", std::string(1 << 16, 'x'));
        ADD_FAILURE() << "written";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), "cannot write '/dev/full': No space left on device");
    }
    EXPECT_FALSE(std::filesystem::is_regular_file("/dev/full"));
    EXPECT_EQ(devslam::core::fileHash((dir / "missing").string()), "");
    // The file keeps its permissions, and a link to it stays a link.
    namespace fs = std::filesystem;
    fs::permissions(f, fs::perms::owner_read | fs::perms::owner_write);
    const fs::path link = dir / "link.txt";
    fs::create_symlink("a.txt", link);
    devslam::core::writeFileWhole(link.string(), "four\n");
    EXPECT_TRUE(fs::is_symlink(link));
    std::ifstream through(f);
    std::getline(through, line);
    EXPECT_EQ(line, "four");
    EXPECT_EQ(fs::status(f).permissions() & fs::perms::all,
              fs::perms::owner_read | fs::perms::owner_write);
    EXPECT_FALSE(fs::exists(dir / "a.txt.part"));
    EXPECT_FALSE(fs::exists(dir / "link.txt.part"));
    // A link to a file not made yet makes it, as a shell's `>` would.
    fs::create_symlink("later.txt", dir / "dangling.txt");
    devslam::core::writeFileWhole((dir / "dangling.txt").string(), "five\n");
    EXPECT_TRUE(fs::is_symlink(dir / "dangling.txt"));
    std::ifstream later(dir / "later.txt");
    std::getline(later, line);
    EXPECT_EQ(line, "five");
    std::filesystem::remove_all(dir);
}

// Writers of one file at once wrote one .part together and renamed a splice of both (two
// runs writing one plot). Each text is one letter repeated: a splice has two letters, a
// reader between renames sees one whole text.
TEST(Results, WritersOfOneFileAtOnceNeverSpliceIt) {
    const auto dir = devslam::test::scratchPath("results_splice");
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const std::string f = (dir / "plot.png").string();
    constexpr std::size_t kSize = 1 << 20;
    const auto whole = [&](const std::string& text) {
        return text.size() == kSize && text.find_first_not_of(text[0]) == std::string::npos;
    };
    std::atomic<bool> done{false};
    std::atomic<int> bad_reads{0}, reads{0};
    std::thread reader([&] {
        while (!done) {
            std::ifstream in(f, std::ios::binary);
            if (!in) continue;
            const std::string got((std::istreambuf_iterator<char>(in)), {});
            ++reads;
            if (!whole(got)) ++bad_reads;
        }
    });
    std::vector<std::thread> writers;
    std::atomic<int> errors{0};
    for (int w = 0; w < 4; ++w)
        writers.emplace_back([&, w] {
            const std::string text(kSize, static_cast<char>('a' + w));
            for (int i = 0; i < 15; ++i) try {
                    devslam::core::writeFileWhole(f, text);
                } catch (const std::exception&) {
                    ++errors;
                }
        });
    for (auto& t : writers) t.join();
    done = true;
    reader.join();
    EXPECT_EQ(errors, 0);
    EXPECT_EQ(bad_reads, 0) << "of " << reads << " reads";
    std::ifstream in(f, std::ios::binary);
    EXPECT_TRUE(whole(std::string((std::istreambuf_iterator<char>(in)), {})));
    EXPECT_FALSE(std::filesystem::exists(f + ".part"));
    // A .part that is a link or a FIFO is in the way (through the link, the rename would have
    // put the link itself at the file's name; a FIFO blocked the write).
    std::filesystem::create_symlink("elsewhere.txt", f + ".part");
    try {
        devslam::core::writeFileWhole(f, "through a link\n");
        ADD_FAILURE() << "written through the link";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()),
                  "cannot write '" + f + "': '" + f + ".part' is in the way (not a plain file)");
    }
    EXPECT_FALSE(std::filesystem::exists(dir / "elsewhere.txt"));
    EXPECT_FALSE(std::filesystem::is_symlink(f));
    std::filesystem::remove(f + ".part");
    ASSERT_EQ(::mkfifo((f + ".part").c_str(), 0600), 0);
    EXPECT_THROW(devslam::core::writeFileWhole(f, "into a FIFO\n"), std::runtime_error);
    std::filesystem::remove(f + ".part");
    // A .part a killed writer left is taken over, not a reason to fail.
    std::ofstream(f + ".part") << "left by a writer killed on the way, longer than the text";
    devslam::core::writeFileWhole(f, "new\n");
    std::ifstream again(f);
    std::string line;
    std::getline(again, line);
    EXPECT_EQ(line, "new");
    EXPECT_FALSE(std::filesystem::exists(f + ".part"));
    std::filesystem::remove_all(dir);
}

TEST(Results, PicturesAreWrittenWholeOrSayWhyNot) {
    const auto dir = devslam::test::scratchPath("results_png");
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const std::string f = (dir / "p.png").string();
    cv::Mat img(40, 60, CV_8UC3, cv::Scalar(10, 200, 30));
    img(cv::Rect(5, 5, 10, 10)).setTo(cv::Scalar(255, 0, 0));
    devslam::core::writePngWhole(f, img);
    const cv::Mat back = cv::imread(f, cv::IMREAD_UNCHANGED);
    ASSERT_EQ(back.size(), img.size());
    EXPECT_EQ(cv::norm(back, img, cv::NORM_INF), 0.0);  // lossless, the same pixels
    EXPECT_FALSE(std::filesystem::exists(f + ".part"));
    // An image PNG cannot hold, an empty one, a folder: named errors, the old picture kept.
    const auto error = [&](const std::string& path, const cv::Mat& m) -> std::string {
        try {
            devslam::core::writePngWhole(path, m);
        } catch (const std::runtime_error& e) {
            return e.what();
        }
        return "written";
    };
    EXPECT_EQ(error(f, cv::Mat(4, 4, CV_8UC2, cv::Scalar(1, 2))),
              "cannot write '" + f + "': the PNG did not encode");
    EXPECT_EQ(error(f, cv::Mat()), "cannot write '" + f + "': the PNG did not encode");
    EXPECT_EQ(error(dir.string(), img), "cannot write '" + dir.string() + "': a folder");
    EXPECT_EQ(cv::norm(cv::imread(f, cv::IMREAD_UNCHANGED), img, cv::NORM_INF), 0.0);
    std::filesystem::remove_all(dir);
}

TEST(Results, MeasuredOnLineNamesTheHostAndItsSimdLevel) {
    const std::string line = measuredOnLine();
    EXPECT_NE(line.find(" UTC, "), std::string::npos) << line;
    EXPECT_NE(line.find(", " + std::to_string(std::thread::hardware_concurrency()) +
                        " hardware threads, "),
              std::string::npos)
        << line;
    // The level of this host: AVX-512 needs the SKX set (F, CD, BW, DQ, VL), not F alone.
    const bool avx512 =
        cv::checkHardwareSupport(CV_CPU_AVX_512F) && cv::checkHardwareSupport(CV_CPU_AVX_512BW) &&
        cv::checkHardwareSupport(CV_CPU_AVX_512DQ) && cv::checkHardwareSupport(CV_CPU_AVX_512VL);
    const std::string simd = avx512                                  ? "AVX-512"
                             : cv::checkHardwareSupport(CV_CPU_AVX2) ? "AVX2"
                                                                     : "SSE/AVX";
    EXPECT_EQ(line.substr(line.rfind(", ") + 2), "OpenCV SIMD " + simd) << line;
}

TEST(Results, ShownPathIsRelativeToTheRepositoryOnlyInsideIt) {
    EXPECT_EQ(shownPath("/repo/config_ini/a.ini", "/repo"), "config_ini/a.ini");
    EXPECT_EQ(shownPath("/repo/x/../config_ini/a.ini", "/repo/"), "config_ini/a.ini");
    EXPECT_EQ(shownPath("/other/a.ini", "/repo"), "/other/a.ini");
    EXPECT_EQ(shownPath("/repository2/a.ini", "/repo"), "/repository2/a.ini");
}

TEST(Association, NearestPairsNeverReused) {
    using P = std::pair<std::size_t, std::size_t>;
    // Candidates (|dt| < 0.02): a1-b0 0.002, a0-b0 0.008, a1-b1 0.015. The closest pair
    // wins, b0 is never reused, a0 stays unmatched (its only other option is 0.025 away).
    EXPECT_EQ(associate({1.000, 1.010, 2.000}, {1.008, 1.025, 2.500}, 0.02),
              (std::vector<P>{{1, 0}}));
    // Greedy order as associate.py: a1-b0 (0.002) first, then a0 falls back to b1 (0.018).
    EXPECT_EQ(associate({1.000, 1.010}, {1.008, 1.018}, 0.02), (std::vector<P>{{0, 1}, {1, 0}}));
    // Unsorted input, offset applied to b.
    EXPECT_EQ(associate({2.0, 1.0}, {0.5, 1.5}, 0.02, 0.5), (std::vector<P>{{1, 0}, {0, 1}}));
    EXPECT_TRUE(associate({1.0}, {}, 0.02).empty());
}

namespace {

/// associate.py itself: every candidate pair, sorted by (|diff|, i, j), taken greedily. What
/// core::associate did until it ran out of memory on dense stamps; the reference it must equal.
std::vector<std::pair<std::size_t, std::size_t>> associateAllPairs(const std::vector<double>& a,
                                                                   const std::vector<double>& b,
                                                                   double max_dt, double offset) {
    std::vector<std::tuple<double, std::size_t, std::size_t>> cand;
    for (std::size_t i = 0; i < a.size(); ++i)
        for (std::size_t j = 0; j < b.size(); ++j)
            if (const double d = std::abs(a[i] - (b[j] + offset)); d < max_dt)
                cand.emplace_back(d, i, j);
    std::sort(cand.begin(), cand.end());
    std::vector<char> used_a(a.size(), 0), used_b(b.size(), 0);
    std::vector<std::pair<std::size_t, std::size_t>> out;
    for (const auto& [d, i, j] : cand) {
        if (used_a[i] || used_b[j]) continue;
        used_a[i] = used_b[j] = 1;
        out.emplace_back(i, j);
    }
    std::sort(out.begin(), out.end(), [&](auto x, auto y) { return a[x.first] < a[y.first]; });
    return out;
}

}  // namespace

// The same pairs as every candidate sorted, over stamps made to tie: equal stamps, stamps on
// a coarse grid (equal differences), unsorted, with offsets, denser and sparser than max_dt.
TEST(Association, EqualsTheAllPairsAlgorithmOnTiesAndDenseStamps) {
    std::mt19937 rng(5);
    std::uniform_int_distribution<int> grid(0, 40);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    for (int trial = 0; trial < 3000; ++trial) {
        const std::size_t na = 1 + rng() % 30, nb = rng() % 30;
        const double step = trial % 3 == 0 ? 0.01 : (trial % 3 == 1 ? 0.0037 : 0.05);
        std::vector<double> a(na), b(nb);
        for (auto& t : a) t = trial % 2 ? 100 + grid(rng) * step : 100 + U(rng) * 0.4;
        for (auto& t : b) t = trial % 2 ? 100 + grid(rng) * step : 100 + U(rng) * 0.4;
        const double max_dt = std::vector<double>{0.02, 0.0371, 0.5}[trial % 3];
        const double offset = trial % 5 == 0 ? 0.01 : 0.0;
        ASSERT_EQ(associate(a, b, max_dt, offset), associateAllPairs(a, b, max_dt, offset))
            << "trial " << trial;
    }
}

// 20 000 stamps 1 us apart, all within max_dt of each other: 4e8 candidates for the
// all-pairs way (6 GB, then std::bad_alloc); here one per stamp. (Every difference is
// 5e-7 s up to rounding, which decides the greedy order: 3000 of them as the reference does.)
TEST(Association, DenseStampsNeedNoMemoryPerCandidate) {
    const auto dense = [](std::size_t n, std::vector<double>& a, std::vector<double>& b) {
        a.resize(n);
        b.resize(n);
        for (std::size_t k = 0; k < n; ++k) {
            a[k] = 1000 + 1e-6 * static_cast<double>(k);
            b[k] = a[k] + 5e-7;
        }
    };
    std::vector<double> a, b;
    dense(3000, a, b);
    EXPECT_EQ(associate(a, b, 0.02), associateAllPairs(a, b, 0.02, 0.0));
    dense(20000, a, b);
    const auto pairs = associate(a, b, 0.02);
    ASSERT_EQ(pairs.size(), a.size());
    std::vector<char> seen(b.size(), 0);
    for (const auto& [i, j] : pairs) {
        EXPECT_LT(std::abs(a[i] - b[j]), 0.02);
        EXPECT_FALSE(seen[j]);
        seen[j] = 1;
    }
}

TEST(GzFile, InnermostMessageSkipsEmptyMessages) {
    const std::string nested =
        "==== MRPT exception ====\nFile: a.cpp\nMessage: outer\n"
        "File: b.cpp\nMessage:   inner text\nCallstack:\n";
    EXPECT_EQ(innermostMessage(nested), "inner text");
    EXPECT_EQ(innermostMessage("plain first line\nsecond"), "plain first line");
    // An empty innermost message keeps the last non-empty one (and must not throw).
    EXPECT_EQ(innermostMessage(nested + "Message:"), "inner text");
    EXPECT_EQ(innermostMessage(nested + "Message:   \nmore"), "inner text");
    EXPECT_EQ(innermostMessage("Message:"), "Message:");
    // An OpenCV error MRPT wraps with its banner alone (a zero-byte external image).
    EXPECT_EQ(innermostMessage("==== MRPT exception ====\nOpenCV(4.6.0) ./modules/imgcodecs/"
                               "src/loadsave.cpp:816: error: (-215:Assertion failed) "
                               "!buf.empty() in function 'imdecode_'\nCall stack backtrace:\n"),
              "OpenCV: (-215:Assertion failed) !buf.empty() in function 'imdecode_'");
    // MRPT's ASSERT_GT_ puts the values on the lines after its message: kept.
    EXPECT_EQ(innermostMessage("==== MRPT exception ====\nFile: a.cpp:12\nMessage: "
                               "ASSERT_GT_(ymax,ymin) failed with\nymax=0\nymin=2.5\n"
                               "Call stack backtrace:\n"),
              "ASSERT_GT_(ymax,ymin) failed with ymax=0, ymin=2.5");
}

// A gzip file written through MRPT's stream interface: read back whole, and a full disk is
// an error naming the file and why, at the write that hit it or at the close.
// A writer that fails with an empty text is a failure: the part file was renamed over the
// file as if it had been written whole (the failure was known by its text alone).
TEST(GzFile, AFailureWithoutATextLeavesTheFileAsItWas) {
    const devslam::test::TempDir d("devslam_gzwhole");
    const std::string path = d.str("m.gridmap");
    std::ofstream(path) << "the old map";
    try {
        devslam::core::writeGzFileWhole(path, "grid map", [](mrpt::io::CStream& s) {
            s.Write("x", 1);
            throw std::runtime_error("");
        });
        ADD_FAILURE() << "a failed write passed";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()),
                  "cannot write grid map '" + path + "': the writer failed without saying why");
    }
    std::ifstream in(path);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "the old map");
    EXPECT_FALSE(std::filesystem::exists(path + ".part"));
}

TEST(GzFile, OutputStreamWritesAGzipFileAndSaysWhyAWriteFailed) {
    const devslam::test::TempDir d("devslam_gz_");
    const std::string path = d.str("a.gz");
    std::string bytes(300000, '\0');
    std::mt19937 g(1);
    for (auto& c : bytes) c = static_cast<char>(g() & 0xff);  // does not compress
    {
        GzOutputStream s(path, 1, "thing");
        EXPECT_EQ(s.Write(bytes.data(), bytes.size()), bytes.size());
        EXPECT_EQ(s.getPosition(), bytes.size());
        EXPECT_NO_THROW(s.close());
        EXPECT_EQ(s.lastError(), "");
    }
    EXPECT_EQ(gzipDamage(path), "");
    // Cut short: zlib's reason alone (it put the file's name in front, and the callers, which
    // name it themselves, said it twice).
    const std::string cut = d.str("cut.gz");
    std::filesystem::copy_file(path, cut);
    std::filesystem::resize_file(cut, std::filesystem::file_size(cut) / 2);
    EXPECT_EQ(gzipDamage(cut), "unexpected end of file");
    EXPECT_THROW(GzOutputStream(d.str("no/such/dir/a.gz"), 1, "thing"), std::runtime_error);
    ASSERT_TRUE(std::filesystem::exists("/dev/full")) << "Linux has /dev/full";
    GzOutputStream full("/dev/full", 1, "thing");
    std::size_t taken = 0;
    for (int k = 0; k < 10 && taken == bytes.size() * static_cast<std::size_t>(k); ++k)
        taken += full.Write(bytes.data(), bytes.size());
    EXPECT_LT(taken, 10 * bytes.size()) << "3 MB into /dev/full, no error";
    EXPECT_EQ(full.lastError(), "No space left on device");
    try {
        full.close();
        ADD_FAILURE() << "closed /dev/full without an error";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()),
                  "error writing thing '/dev/full': its end was not written (disk full?), the "
                  "file is cut short");
    }
}

namespace {
// zlib's own verdict on a file, as gzipDamage gave it until gzipCheck read the file once for
// both of its answers: gzread to the end, then gzerror without the file's name.
std::string gzreadDamage(const std::string& path) {
    gzFile f = gzopen(path.c_str(), "rb");
    if (f == nullptr) return "cannot open";
    std::vector<char> buf(1 << 16);
    int n = 0;
    while ((n = gzread(f, buf.data(), static_cast<unsigned>(buf.size()))) > 0) {
    }
    int err = Z_OK;
    const char* msg = gzerror(f, &err);
    std::string out = (n < 0 || (err != Z_OK && err != Z_STREAM_END)) ? msg : "";
    gzclose(f);
    if (out.rfind(path + ": ", 0) == 0) out.erase(0, path.size() + 2);
    return out;
}
}  // namespace

// gzipCheck inflates the file itself (to find where the gzip data ends) and must tell its
// damage as zlib's gzread does: every cut, every flipped byte of the header and trailer and
// some in the data, and what may follow a whole stream. Its messages are those of the text
// rawlog and map errors quote.
TEST(GzFile, OneReadThroughGivesZlibsOwnVerdictAndWhatFollowsTheStream) {
    const devslam::test::TempDir d("devslam_gzcheck");
    std::string data(200000, '\0');
    std::mt19937 g(7);
    for (std::size_t i = 0; i < data.size(); ++i)  // half compressible, half not
        data[i] = static_cast<char>(i < data.size() / 2 ? (i / 97) & 0xff : g() & 0xff);
    const std::string whole_path = d.str("whole.gz");
    {
        GzOutputStream s(whole_path, 1, "thing");
        s.Write(data.data(), data.size());
        s.close();
    }
    std::ifstream in(whole_path, std::ios::binary);
    const std::string whole((std::istreambuf_iterator<char>(in)), {});
    ASSERT_GT(whole.size(), 100000u);
    const std::string path = d.str("f");
    const auto write = [&](const std::string& bytes) {
        std::ofstream(path, std::ios::binary) << bytes;
    };
    std::size_t compared = 0, damaged = 0;
    const auto same = [&](const std::string& bytes, const std::string& what) {
        write(bytes);
        const GzipCheck c = gzipCheck(path);
        EXPECT_EQ(c.damage, gzreadDamage(path)) << what;
        if (!c.damage.empty()) {
            ++damaged;
            EXPECT_EQ(c.trailing, "") << what;
        }
        ++compared;
        return c;
    };
    EXPECT_EQ(same(whole, "whole").damage, "");
    std::vector<std::size_t> cuts = {0, 1, 2, 3, 9, 10, 11, 5000, whole.size() / 2};
    for (std::size_t k = 1; k <= 9; ++k) cuts.push_back(whole.size() - k);  // in the trailer
    for (std::size_t n : cuts) same(whole.substr(0, n), "cut at " + std::to_string(n));
    EXPECT_EQ(gzipCheck(path).damage, "unexpected end of file");  // the last: 1 byte short
    std::vector<std::size_t> flips = {0, 1, 2, 3, 4, 8, 9, 10, 100, whole.size() / 2};
    for (std::size_t k = 1; k <= 8; ++k) flips.push_back(whole.size() - k);
    for (std::size_t at : flips)
        for (unsigned char mask : {0x01, 0x80, 0xff}) {
            std::string b = whole;
            b[at] = static_cast<char>(b[at] ^ mask);
            same(b, "byte " + std::to_string(at) + " ^ " + std::to_string(mask));
        }
    EXPECT_EQ(gzipCheck(path).damage, "incorrect data check");  // the last: a CRC byte flipped
    // No gzip at all: zlib passes it through, as MRPT reads a plain rawlog.
    EXPECT_EQ(same("", "empty").damage, "");
    EXPECT_EQ(same("\x1f", "one magic byte").damage, "");
    EXPECT_EQ(same("plain text, no gzip", "text").damage, "");
    // After a whole stream: a second member is read on; anything else is what follows it.
    EXPECT_EQ(same(whole + whole, "two members").trailing, "");
    same(whole + whole.substr(0, 500), "a second member cut short");
    const std::string after =
        " after the end of its gzip data at byte " + std::to_string(whole.size());
    EXPECT_EQ(same(whole + "\x1f", "a lone magic byte after it").trailing,
              "1 byte" + after + " is no gzip stream (another file appended, or damage)");
    EXPECT_EQ(same(whole + "x" + whole.substr(1), "a member with its first byte changed").trailing,
              std::to_string(whole.size()) + " bytes" + after +
                  " are no gzip stream (another file appended, or damage)");
    EXPECT_EQ(same(whole + std::string(70000, '\0'), "zeros after it").trailing,
              "70000 bytes" + after + " are no gzip stream (another file appended, or damage)");
    // Not a file to read: zlib's reason.
    EXPECT_EQ(gzipCheck(d.str("no_such.gz")).damage, "cannot open");
    EXPECT_EQ(gzipCheck(d.str("")).damage, gzreadDamage(d.str("")));  // the folder
    EXPECT_EQ(gzipCheck(d.str("")).damage, "Is a directory");
    EXPECT_GT(damaged, 40u) << "of " << compared;  // the comparisons are not all of whole files
    // Stopped from outside: it returns before reading on, and says so. Not stopped, it
    // counts the bytes it read: all of them.
    GzipCheckControl control;
    control.stop = true;
    write(whole.substr(0, whole.size() / 2));
    const GzipCheck stopped = gzipCheck(path, &control);
    EXPECT_TRUE(stopped.stopped);
    EXPECT_EQ(stopped.damage, "");
    control.stop = false;
    const GzipCheck run = gzipCheck(path, &control);
    EXPECT_FALSE(run.stopped);
    EXPECT_EQ(run.damage, "unexpected end of file");
    EXPECT_EQ(control.bytes_read, whole.size() / 2);
}

// An output folder held for a run: a second claim (a second run into it at once) is refused;
// a folder the claim made and nothing was written into goes with it.
TEST(Results, FolderClaimRefusesASecondWriterAndTakesBackAnEmptyFolderItMade) {
    const devslam::test::TempDir d("devslam_core_");
    const std::string dir = d.str("a/b");
    {
        const FolderClaim first(dir);
        EXPECT_TRUE(std::filesystem::is_directory(dir));
        try {
            const FolderClaim second(dir);
            ADD_FAILURE() << "two claims on one folder";
        } catch (const std::runtime_error& e) {
            EXPECT_EQ(std::string(e.what()), "'" + dir +
                                                 "' is being written by another run at the "
                                                 "moment; wait for it or name another folder");
        }
    }
    EXPECT_FALSE(std::filesystem::exists(dir)) << "made, empty, and left";
    {
        const FolderClaim again(dir);
        std::ofstream(dir + "/out.txt") << "x";
    }
    EXPECT_TRUE(std::filesystem::exists(dir + "/out.txt"));
    { const FolderClaim kept(dir); }  // there before: stays, even if it were empty
    EXPECT_TRUE(std::filesystem::is_directory(dir));
    std::filesystem::create_symlink(d.str("nowhere"), d.str("link"));
    try {
        const FolderClaim broken(d.str("link"));
        ADD_FAILURE() << "claimed a link to nothing";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), "cannot make folder '" + d.str("link") +
                                             "': it is a link to '" + d.str("nowhere") +
                                             "', which is not there");
    }
}

TEST(Stats, MatchesNumpy) {
    const auto s = summarize({1, 2, 3, 4});
    EXPECT_DOUBLE_EQ(s.mean, 2.5);
    EXPECT_DOUBLE_EQ(s.median, 2.5);
    EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
    EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));
    EXPECT_DOUBLE_EQ(s.min, 1);
    EXPECT_DOUBLE_EQ(s.max, 4);
    EXPECT_DOUBLE_EQ(median({5, 1, 3}), 3);
    EXPECT_EQ(summarize({}).count, 0u);
}

TEST(Stats, InterquartileMean) {
    EXPECT_DOUBLE_EQ(interquartileMean({}), 0);
    EXPECT_DOUBLE_EQ(interquartileMean({7}), 7);
    EXPECT_DOUBLE_EQ(interquartileMean({4, 1, 3, 2}), 2.5);  // drops 1 and 4
    // An outlier among eight is dropped, as by the median.
    EXPECT_DOUBLE_EQ(interquartileMean({1, 1, 1, 1, 1, 1, 1, 100}), 1);
    // Depth residuals in 2 cm steps, 11 of 20 points unchanged (static, or not across a
    // step this frame) and 9 a step deeper: the median says 0, the interquartile mean
    // keeps the change (the mean of the middle ten, 4 x 0.02 / 10).
    std::vector<double> steps(11, 0.0);
    steps.insert(steps.end(), 9, 0.02);
    EXPECT_DOUBLE_EQ(median(steps), 0.0);
    EXPECT_NEAR(interquartileMean(steps), 0.008, 1e-12);
}

// The 95 % interval of a mean from a few samples is Student's, not the normal 1.96 sigma.
TEST(Stats, MeanInterval95UsesStudentsT) {
    const auto m = meanInterval95({1, 2, 3, 4, 5});
    EXPECT_EQ(m.count, 5u);
    EXPECT_DOUBLE_EQ(m.mean, 3);
    // s = sqrt(2.5); t(0.975, 4 dof) = 2.7764451051977987 (tables: 2.776)
    const double half = 2.7764451051977987 * std::sqrt(2.5) / std::sqrt(5.0);
    EXPECT_NEAR(m.lo, 3 - half, 1e-9);
    EXPECT_NEAR(m.hi, 3 + half, 1e-9);
    // Two samples: t(0.975, 1 dof) = 12.706, the interval is wide.
    const auto two = meanInterval95({1, 3});
    EXPECT_NEAR(two.hi - two.mean, 12.706204736174707 * std::sqrt(2.0) / std::sqrt(2.0), 1e-9);
    // One value: its mean, no interval; none: nothing.
    const auto one = meanInterval95({7});
    EXPECT_DOUBLE_EQ(one.mean, 7);
    EXPECT_TRUE(std::isnan(one.lo) && std::isnan(one.hi));
    const auto none = meanInterval95({});
    EXPECT_EQ(none.count, 0u);
    EXPECT_TRUE(std::isnan(none.mean));
}

TEST(Pose, TumQuaternionRoundTrip) {
    const auto p = fromTum(1, 2, 3, 0.6132, 0.5962, -0.3311, -0.3986);
    EXPECT_NEAR(p.x(), 1, 1e-12);
    const auto T = toIsometry(p);
    EXPECT_TRUE(
        toCPose3D(T).getHomogeneousMatrixVal<mrpt::math::CMatrixDouble44>().asEigen().isApprox(
            T.matrix(), 1e-12));
    EXPECT_THROW((void)fromTum(0, 0, 0, 0, 0, 0, 2), std::invalid_argument);
    EXPECT_NEAR(rotationAngle(mrpt::poses::CPose3D(0, 0, 0, 0.3, 0, 0)), 0.3, 1e-12);
    EXPECT_NEAR(wrapToPi(3 * M_PI / 2), -M_PI / 2, 1e-12);
    EXPECT_NEAR(wrapToPi(M_PI), M_PI, 1e-12);
}

TEST(Frame, ValidateNamesTheProblem) {
    Frame f;
    f.bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar(0));
    f.depth = cv::Mat(480, 640, CV_32FC1, cv::Scalar(1.0f));
    EXPECT_NO_THROW(validateFrame(f, "x"));
    const auto problem = [&] {
        try {
            validateFrame(f, "x.png");
        } catch (const std::runtime_error& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    f.depth = cv::Mat(240, 320, CV_32FC1, cv::Scalar(1.0f));
    EXPECT_EQ(problem(), "x.png: depth is 320x240 but colour is 640x480");
    f.depth = cv::Mat(480, 640, CV_16UC1);
    EXPECT_EQ(problem(), "x.png: depth must be float metres (CV_32FC1)");
    f.depth = cv::Mat(480, 640, CV_32FC1, cv::Scalar(1.0f));
    f.K.width = 320;
    EXPECT_EQ(problem(), "x.png: intrinsics are for 320x" + std::to_string(f.K.height) +
                             " but the image is 640x480");
}

// The first SIGINT/SIGTERM is recorded and the program goes on; a child's std::system status
// tells a stop by signal (killed by it, or exited 128 + it after finishing its step).
TEST(Interrupt, FirstSignalIsRecordedAndChildStatusesAreRead) {
    // A signal ignored at start stays ignored (a shell's background job's SIGINT).
    std::signal(SIGINT, SIG_IGN);
    devslam::core::installStopHandler("test_core");
    devslam::core::clearStopSignal();
    ASSERT_EQ(std::raise(SIGINT), 0);
    EXPECT_EQ(devslam::core::stopSignal(), 0);
    ASSERT_EQ(std::raise(SIGTERM), 0);
    EXPECT_EQ(devslam::core::stopSignal(), SIGTERM);  // still running
    struct sigaction now {};
    ASSERT_EQ(sigaction(SIGINT, nullptr, &now), 0);
    EXPECT_EQ(now.sa_handler, SIG_IGN);  // the first signal reset only what was installed
    ASSERT_EQ(sigaction(SIGTERM, nullptr, &now), 0);
    EXPECT_EQ(now.sa_handler, SIG_DFL);  // a second SIGTERM would end the program
    devslam::core::clearStopSignal();
    EXPECT_EQ(devslam::core::signalName(SIGINT), "SIGINT");
    EXPECT_EQ(devslam::core::signalName(SIGTERM), "SIGTERM");
    std::signal(SIGINT, SIG_DFL);  // the children below inherit it
    using devslam::core::stopSignalOf;
    EXPECT_EQ(stopSignalOf(std::system("kill -INT $$")), SIGINT);
    EXPECT_EQ(stopSignalOf(std::system("kill -TERM $$")), SIGTERM);
    EXPECT_EQ(stopSignalOf(std::system("exit 130")), SIGINT);
    EXPECT_EQ(stopSignalOf(std::system("exit 143")), SIGTERM);
    EXPECT_EQ(stopSignalOf(std::system("exit 0")), 0);
    EXPECT_EQ(stopSignalOf(std::system("exit 1")), 0);
    EXPECT_EQ(stopSignalOf(std::system("kill -KILL $$")), 0);
    // runCommand: the shell execs the program, so the program is the caller's child, which
    // a signal to the child reaches (std::system's shell would die of SIGTERM at once and
    // leave the program running); the program's status comes back.
    EXPECT_EQ(devslam::core::runCommand("sh -c 'test $PPID -eq " + std::to_string(getpid()) +
                                        " && exit 3' > /dev/null"),
              3 << 8);
    EXPECT_EQ(devslam::core::stopSignalOf(devslam::core::runCommand("sh -c 'kill -TERM $$'")),
              SIGTERM);
}

// exitBySignal ends the program by the signal itself (a shell sees it killed, not exit 130),
// after flushing what it printed.
TEST(Interrupt, ExitBySignalEndsByTheSignal) {
    EXPECT_EXIT(
        {
            std::setvbuf(stderr, nullptr, _IOFBF, 4096);  // held until flushed
            std::fprintf(stderr, "flushed");
            devslam::core::exitBySignal(SIGINT);
        },
        testing::KilledBySignal(SIGINT), "flushed");
}
