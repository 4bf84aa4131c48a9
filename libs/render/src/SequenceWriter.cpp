#include <devslam/core/Parse.h>
#include <devslam/core/Picture.h>
#include <devslam/core/Results.h>
#include <devslam/core/Stats.h>
#include <devslam/io/Rawlog.h>
#include <devslam/io/TumWriter.h>
#include <devslam/render/SequenceRenderer.h>
#include <devslam/render/SequenceWriter.h>

#include <mrpt/config/CConfigFileMemory.h>
#include <opencv2/core.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace devslam::render {
namespace fs = std::filesystem;

namespace {

std::string readWholeFile(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw std::runtime_error("cannot read '" + path + "'");
    std::ostringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

fs::path signaturePath(const WriteOptions& o) {
    return fs::path(o.out_dir) / "render.txt";
}

fs::path personsPath(const WriteOptions& o) {
    return fs::path(o.out_dir) / "persons.txt";
}

/// Whether the output folder is a render of ours, whole (render.txt) or stopped (persons.txt,
/// which every render writes before rgb.txt).
bool isOwnRender(const WriteOptions& o) {
    return fs::exists(signaturePath(o)) || fs::exists(personsPath(o));
}

/// The line naming the rawlog a render writes (render.txt; "# " before it in persons.txt).
std::string rawlogLine(const WriteOptions& o) {
    return "rawlog " + fs::absolute(o.rawlog_path).string();
}

/// Whether the text file `path` exists and has a line equal to `line`.
bool hasLine(const fs::path& path, const std::string& line) {
    std::ifstream f(path);
    for (std::string l; std::getline(f, l);)
        if (l == line) return true;
    return false;
}

/// An INI file's settings as text: comments (# and ; lines, // to the end of a line), blank
/// lines and spaces at the ends dropped, so that editing a comment keeps a render current.
std::string iniSettings(const std::string& path) {
    std::istringstream in(readWholeFile(path));
    std::string line, out;
    while (std::getline(in, line)) {
        if (const auto c = line.find("//"); c != std::string::npos) line.erase(c);
        const auto b = line.find_first_not_of(" \t\r");
        if (b == std::string::npos || line[b] == '#' || line[b] == ';') continue;
        const auto e = line.find_last_not_of(" \t\r");
        out += line.substr(b, e - b + 1) + "\n";
    }
    return out;
}

}  // namespace

std::string renderSignature(const Scenario& sc, const WriteOptions& o) {
    const std::size_t n = o.max_frames > 0 ? std::min(o.max_frames, sc.n_frames) : sc.n_frames;
    std::ostringstream s;
    s << "# devslam-synth render: a rerun with the same content would write the same files\n"
      << "renderer_version " << kRendererVersion << "\nseed " << sc.seed << "\nframes " << n
      << "\nlabels " << int(o.write_labels) << "\n";
    for (const auto& file : {sc.source, sc.room.source})
        if (!file.empty()) s << "--- " << file << "\n" << iniSettings(file);
    for (const auto& item : sc.overrides) s << "set " << item << "\n";
    // Written in the same pass: a render without it, or into another file, is another render.
    if (!o.rawlog_path.empty()) s << rawlogLine(o) << "\n";
    // Texture contents are not hashed: their paths and sizes catch a replaced photo of
    // another size, not one of the very same byte count.
    std::vector<std::string> textures = sc.room.wall_textures;
    textures.insert(textures.end(), sc.room.floor_textures.begin(), sc.room.floor_textures.end());
    for (const auto& b : sc.room.boxes)
        textures.insert(textures.end(), b.textures.begin(), b.textures.end());
    for (const auto& p : sc.people) textures.push_back(p.texture);
    for (const auto& t : textures) {
        std::error_code ec;
        const auto size = fs::file_size(t, ec);
        s << "texture " << t << " " << (ec ? std::string("missing") : std::to_string(size)) << "\n";
    }
    return s.str();
}

bool isRenderCurrent(const Scenario& sc, const WriteOptions& o) {
    if (!o.rawlog_path.empty() && !fs::is_regular_file(o.rawlog_path)) return false;
    std::ifstream f(signaturePath(o), std::ios::binary);
    if (!f) return false;
    std::ostringstream ss;
    ss << f.rdbuf();
    return ss.str() == renderSignature(sc, o);
}

void checkOutputs(const Scenario& sc, const WriteOptions& o) {
    const fs::path dir(o.out_dir);
    // A real TUM folder's lists and ground truth would be overwritten (devslam-convert refuses
    // one too); a render of ours, whole or stopped, has persons.txt (written before rgb.txt).
    if (!o.out_dir.empty() && fs::exists(dir / "rgb.txt") && !isOwnRender(o))
        throw std::invalid_argument(
            "output folder '" + o.out_dir +
            "' already holds a TUM sequence (rgb.txt) that devslam-synth did not render (no "
            "render.txt or persons.txt); remove it or name another folder");
    // Nor are another folder's labels/, ground truth, camera.ini or preview.png, which a
    // render replaces (a YOLO dataset's labels/ went without a word).
    if (!o.out_dir.empty() && !isOwnRender(o))
        for (const char* name :
             {"labels", "groundtruth.txt", "camera.ini", "preview.png", "rgb", "depth"})
            if (fs::exists(dir / name))
                throw std::invalid_argument("output folder '" + o.out_dir + "' holds " + name +
                                            ", not of a devslam-synth render (no render.txt or "
                                            "persons.txt); remove it or name another folder");
    // A folder under the name of a file the render writes: render.txt, groundtruth.txt and
    // camera.ini failed after the last frame (minutes of render lost, "cannot write" without
    // a reason), preview.png in the middle with a bare filesystem error.
    for (const char* name : {"render.txt", "groundtruth.txt", "camera.ini", "persons.txt",
                             "rgb.txt", "depth.txt", "preview.png"}) {
        std::error_code ec;
        const auto st = fs::status(dir / name, ec);
        if (!o.out_dir.empty() && fs::exists(st) && !fs::is_regular_file(st))
            throw std::invalid_argument("'" + (dir / name).string() +
                                        "' is not a file: the render writes its " + name +
                                        " there; move it or name another folder");
    }
    if (o.rawlog_path.empty()) return;
    const std::string ext = ".rawlog";
    const auto& r = o.rawlog_path;
    if (r.size() <= ext.size() || !core::endsWith(r, ext))
        throw std::invalid_argument("rawlog '" + r + "': the name must end in .rawlog");
    for (const auto& [what, file] : {std::pair{"scenario", sc.source}, {"room", sc.room.source}})
        if (!file.empty() && core::sameFile(file, r))
            throw std::invalid_argument("rawlog '" + r + "' is the " + what + " file '" + file +
                                        "': writing it would destroy it; name another");
    // Found here, not when the writer opens it: by then the folder's earlier render had lost
    // its ground truth and lists (an unwritable --rawlog cost a whole render).
    if (fs::is_directory(r)) throw std::invalid_argument("rawlog '" + r + "' is a folder");
    const fs::path parent = core::nearestExisting(fs::path(r).parent_path().string());
    if (!fs::is_directory(parent) || !core::canMakeFilesIn(parent))
        throw std::invalid_argument("rawlog '" + r + "': cannot write in '" + parent.string() +
                                    "'");
    // A rawlog this folder's render did not write is someone's data (devslam-convert refuses
    // to overwrite one too). The render names the one it writes in persons.txt, from the
    // start, and in render.txt, at the end: a stopped render is resumed into the same file.
    const std::string mine = rawlogLine(o);
    if (fs::exists(r) && !hasLine(personsPath(o), "# " + mine) &&
        !hasLine(signaturePath(o), mine))
        throw std::invalid_argument("rawlog '" + r + "' exists and is not one that a render into '" +
                                    o.out_dir + "' wrote; remove it or name another");
}

WriteSummary writeSequence(const Scenario& sc, const WriteOptions& o,
                           const std::function<void(std::size_t, std::size_t)>& progress) {
    if (o.out_dir.empty()) throw std::invalid_argument("writeSequence: empty output folder");
    checkOutputs(sc, o);
    const std::string signature = renderSignature(sc, o);
    // Made before any output is touched: it takes a while (photos, blurred panels, the EGL
    // context), and a stop asked meanwhile, or its failure, leaves the folder as it was.
    SequenceRenderer renderer(sc);
    // Stopped before it began: the folder (perhaps a whole earlier render) is left as it was.
    if (o.stop && o.stop()) {
        WriteSummary none;
        none.stopped = true;
        return none;
    }
    // Until the last frame is written the folder is not a current render; an earlier
    // render's ground truth and intrinsics go too, so that a run killed half-way leaves no
    // old trajectory beside the new frames (written again at the end, or at a stop).
    // (checkOutputs refused a folder not ours that has images.)
    const bool ours = isOwnRender(o);
    std::error_code ec;
    fs::remove(signaturePath(o), ec);
    fs::remove(fs::path(o.out_dir) / "groundtruth.txt", ec);
    fs::remove(fs::path(o.out_dir) / "camera.ini", ec);
    const std::size_t n = o.max_frames > 0 ? std::min(o.max_frames, sc.n_frames) : sc.n_frames;
    // persons.txt before rgb.txt: a folder with rgb.txt and neither it nor render.txt is
    // no render of ours (checkOutputs), even when a run ended between the two.
    fs::create_directories(o.out_dir, ec);
    const std::string persons_path = personsPath(o).string();
    std::ofstream persons(persons_path);
    if (!persons) throw std::runtime_error("cannot write '" + persons_path + "'");
    persons << "# person truth of devslam-synth scenario " << sc.name << "\n"
            << (o.rawlog_path.empty() ? std::string() : "# " + rawlogLine(o) + "\n")
            << kPersonsHeader << "\n";
    // An earlier, longer render's images past this one's last frame stayed, unlisted.
    if (ours)
        for (const char* images : {"rgb", "depth"}) fs::remove_all(fs::path(o.out_dir) / images);
    io::TumWriter tum(o.out_dir, "devslam-synth scenario " + sc.name);
    std::unique_ptr<io::RawlogWriter> rawlog;
    if (!o.rawlog_path.empty())
        rawlog = std::make_unique<io::RawlogWriter>(o.rawlog_path, io::RawlogWriterOptions{});
    // Another render's labels would pass for this one's truth (PersonTruth reads the folder).
    fs::remove_all(fs::path(o.out_dir) / "labels");
    if (o.write_labels) fs::create_directories(fs::path(o.out_dir) / "labels");

    core::Trajectory gt;
    WriteSummary sum;
    std::vector<double> ms, depth_fraction;
    std::size_t i = 0;
    for (; i < n; ++i) {
        // Not before the first frame: the earlier render's files are gone already, and a
        // stop with none written would leave a folder that is neither render.
        if (i > 0 && o.stop && o.stop()) {
            sum.stopped = true;
            break;
        }
        const auto t0 = std::chrono::steady_clock::now();
        const RenderedFrame rf = renderer.render(i);
        ms.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count());
        tum.write(rf.frame);
        if (rawlog) rawlog->write(rf.frame);
        gt.push_back({rf.frame.timestamp, rf.T_wc});
        char stamp[64];
        std::snprintf(stamp, sizeof stamp, "%.6f", rf.frame.timestamp);
        bool moving_visible = false, static_visible = false;
        for (const auto& p : rf.persons) {
            persons << stamp << ' ' << p.id << ' ' << p.name << ' '
                    << (p.moving ? "moving" : "static") << ' ' << p.box.x << ' ' << p.box.y << ' '
                    << p.box.width << ' ' << p.box.height << ' ' << p.visible_pixels << '\n';
            if (p.visible_pixels > 0) (p.moving ? moving_visible : static_visible) = true;
        }
        sum.frames_with_moving_person += moving_visible;
        sum.frames_with_static_person += static_visible;
        const int with_depth = cv::countNonZero(rf.frame.depth > 0);
        depth_fraction.push_back(static_cast<double>(with_depth) /
                                 static_cast<double>(rf.frame.depth.total()));
        if (with_depth == 0 && cv::countNonZero(rf.clean_depth > 0) > 0) ++sum.frames_without_depth;
        if (o.write_labels) {
            const std::string lp =
                (fs::path(o.out_dir) / "labels" / (std::string(stamp) + ".png")).string();
            core::writePngWhole(lp, rf.labels);
        }
        if (o.on_frame) o.on_frame(i, rf);
        if (progress) progress(i + 1, n);
    }
    persons.close();
    if (!persons) throw std::runtime_error("error writing '" + persons_path + "'");
    tum.writeGroundTruth(gt);
    tum.close();
    if (rawlog) rawlog->close();

    // The exact intrinsics of the rendered images, in the [camera] format core reads.
    mrpt::config::CConfigFileMemory cam;
    sc.K.saveToConfig(cam, "camera");
    std::string text;
    cam.getContent(text);
    const std::string cam_path = (fs::path(o.out_dir) / "camera.ini").string();
    std::ofstream cf(cam_path);
    cf << "# exact pinhole intrinsics of this synthetic sequence (no distortion), scenario "
       << sc.name << "\n"
       << text;
    cf.close();  // flushed here: a full disk is found now, before render.txt says "whole"
    if (!cf) throw std::runtime_error("cannot write '" + cam_path + "'");

    sum.n_frames = i;
    sum.render_ms_median = core::median(ms);
    sum.depth_fraction_median = depth_fraction.empty() ? 0.0 : core::median(depth_fraction);
    if (sum.stopped) return sum;  // not this render's frame count: no render.txt
    const std::string sig_path = signaturePath(o).string();
    std::ofstream sf(sig_path, std::ios::binary);
    sf << signature;
    sf.close();
    if (!sf) throw std::runtime_error("cannot write '" + sig_path + "'");
    return sum;
}

}  // namespace devslam::render
