#include <devslam/core/Config.h>
#include <devslam/core/Parse.h>
#include <devslam/render/PersonTexture.h>
#include <devslam/render/Scenario.h>

#include <mrpt/config/CConfigFileBase.h>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

namespace devslam::render {
namespace fs = std::filesystem;
namespace {

/// "the room (0..X x 0..Y x 0..Z m)", for the errors that place something outside it.
std::string roomExtent(const Eigen::Vector3d& R) {
    std::ostringstream m;
    m << "the room (0.." << R.x() << " x 0.." << R.y() << " x 0.." << R.z() << " m)";
    return m.str();
}

/// A key that must be given: "[section] key: missing" (MRPT's own required read throws
/// a stack trace that names neither).
std::string requiredText(const mrpt::config::CConfigFileBase& c, const std::string& section,
                         const std::string& key) {
    const std::string v = c.read_string(section, key, "");
    if (v.empty()) throw std::invalid_argument("[" + section + "] " + key + ": missing");
    return v;
}

constexpr double kPi = 3.14159265358979323846;

std::string dirOf(const std::string& path) {
    const fs::path p = fs::absolute(path).parent_path();
    return p.string();
}

/// Resolves a whitespace-separated list of files/folders (relative to `base`) into files.
std::vector<std::string> resolveImages(const std::string& list, const std::string& base,
                                       const std::string& what) {
    std::vector<std::string> out;
    std::istringstream ss(list);
    std::string tok;
    while (ss >> tok) {
        fs::path p(tok);
        if (p.is_relative()) p = fs::path(base) / p;
        p = p.lexically_normal();
        if (fs::is_directory(p)) {
            std::vector<std::string> files;
            for (const auto& e : fs::directory_iterator(p)) {
                const auto ext = e.path().extension().string();
                if (ext == ".png" || ext == ".jpg" || ext == ".jpeg")
                    files.push_back(e.path().string());
            }
            std::sort(files.begin(), files.end());
            if (files.empty())
                throw std::runtime_error(what + ": folder '" + p.string() + "' has no images");
            out.insert(out.end(), files.begin(), files.end());
        } else if (fs::is_regular_file(p)) {
            out.push_back(p.string());
        } else {
            // (a device or a pipe was "no such file", which is there)
            throw std::runtime_error(
                what + ": '" + p.string() + "' " +
                (fs::exists(p) ? "is no regular file or folder" : "is no such file or folder"));
        }
    }
    // Checked here, where the key is known (the renderer, which reads them at the first
    // frame, could name only the file): OpenCV must have a decoder for each one's bytes.
    for (const auto& f : out)
        if (!cv::haveImageReader(f))
            throw std::runtime_error(what + ": '" + f +
                                     "' is not an image OpenCV can read (or cannot be opened)");
    return out;
}

Eigen::Vector3d vec3(const mrpt::config::CConfigFileBase& cfg, const std::string& s,
                     const std::string& key, const std::string& src, bool required,
                     const Eigen::Vector3d& def = Eigen::Vector3d::Zero()) {
    const auto txt = core::readTextIfPresent(cfg, s, key);
    if (!txt) {
        if (required) throw std::invalid_argument(src + " [" + s + "]: missing key '" + key + "'");
        return def;
    }
    const auto v = core::parseNumberList(*txt, src + " [" + s + "] " + key, 3);
    return {v[0], v[1], v[2]};
}

std::vector<std::string> sectionsWithPrefix(const mrpt::config::CConfigFileBase& cfg,
                                            const std::string& prefix) {
    std::vector<std::string> all, out;
    cfg.getAllSections(all);
    for (const auto& s : all)
        if (s.rfind(prefix, 0) == 0) out.push_back(s);
    std::sort(out.begin(), out.end());
    return out;
}

void readRoom(const std::string& path, RoomSpec& room) {
    const auto cfg = core::loadIni(path);
    core::requireKnownSections(*cfg, {"room", "box_*"}, path);
    // The scenario's room_set: only sections the room file has (every one of them is [room]
    // or a [box_*], checked above), else a typo in a section name would add a section: a box
    // without `base` or an unknown one, with a message that does not say what went wrong
    // (keys are checked below, as the file's own).
    for (const auto& item : room.overrides) {
        const auto dot = item.find('.');
        if (dot == std::string::npos) continue;  // malformed: applyOverrides says how
        const std::string sec = item.substr(0, dot);
        if (!cfg->sectionExists(sec))
            throw std::invalid_argument("room_set item '" + item + "': the room file has no [" +
                                        sec + "] section to set (sections: room, box_*)");
    }
    core::applyOverrides(*cfg, room.overrides, "room_set item");
    const std::string base = dirOf(path);
    const std::string s = "room";
    core::requireKnownKeys(*cfg, s,
                           {"size", "panel_width", "panel_height", "wall_textures",
                            "floor_textures", "wall_blur", "floor_blur"},
                           path);
    room.source = path;
    room.size = vec3(*cfg, s, "size", path, true);
    room.panel_width = core::readDouble(*cfg, s, "panel_width", room.panel_width);
    room.panel_height = core::readDouble(*cfg, s, "panel_height", room.panel_height);
    core::requireValue(room.size.minCoeff() > 0.5, "room", "size", "each side > 0.5 [m]");
    core::requireValue(room.panel_width > 0.05, "room", "panel_width", "must be > 0.05 [m]");
    core::requireValue(room.panel_height > 0.05, "room", "panel_height", "must be > 0.05 [m]");
    {  // Every panel holds a photo crop of its own: a 10 km room ran out of memory.
        const auto n = [](double len, double panel) { return std::ceil(len / panel); };
        const double X = room.size.x(), Y = room.size.y(), Z = room.size.z();
        const double pw = room.panel_width, ph = room.panel_height;
        const double panels = 2 * (n(X, pw) + n(Y, pw)) * n(Z, ph) + 2 * n(X, pw) * n(Y, ph);
        std::ostringstream m;
        m << "a room of " << X << " x " << Y << " x " << Z << " m in panels of " << pw << " x "
          << ph << " m has " << panels << " panels (at most 5000)";
        core::requireValue(panels <= 5000, "room", "size", m.str());
    }
    room.wall_blur = core::readDouble(*cfg, s, "wall_blur", 0.0);
    room.floor_blur = core::readDouble(*cfg, s, "floor_blur", 0.0);
    core::requireValue(room.wall_blur >= 0 && room.wall_blur <= 100, "room", "wall_blur",
                       "must be 0..100 [px]");
    core::requireValue(room.floor_blur >= 0 && room.floor_blur <= 100, "room", "floor_blur",
                       "must be 0..100 [px]");
    room.wall_textures =
        resolveImages(requiredText(*cfg, s, "wall_textures"), base, path + " [room] wall_textures");
    room.floor_textures = resolveImages(requiredText(*cfg, s, "floor_textures"), base,
                                        path + " [room] floor_textures");
    for (const auto& b : sectionsWithPrefix(*cfg, "box_")) {
        // As [person_]: a [box_] was a box with no name, which room_set could not reach.
        if (b.size() <= std::string("box_").size())
            throw std::invalid_argument(path + " [" + b +
                                        "]: a box's section needs a name after 'box_'");
        core::requireKnownKeys(*cfg, b, {"base", "size", "yaw_deg", "textures", "blur"}, path);
        BoxSpec box;
        box.name = b;
        box.base = vec3(*cfg, b, "base", path, true);
        box.size = vec3(*cfg, b, "size", path, true);
        core::requireValue(box.size.minCoeff() > 0, b, "size", "must be > 0 [m]");
        {  // Outside the room (or under its floor) a box rendered as nothing, without a word.
            const auto& R = room.size;
            const auto& p = box.base;
            std::ostringstream m;
            m << "(" << p.x() << ", " << p.y() << ", " << p.z() << ") lies outside "
              << roomExtent(R);
            core::requireValue(p.x() > 0 && p.x() < R.x() && p.y() > 0 && p.y() < R.y() &&
                                   p.z() >= 0 && p.z() < R.z(),
                               b, "base", m.str());
        }
        box.yaw = core::readDouble(*cfg, b, "yaw_deg", 0.0) * kPi / 180.0;
        box.textures =
            resolveImages(requiredText(*cfg, b, "textures"), base, path + " [" + b + "] textures");
        box.blur = core::readDouble(*cfg, b, "blur", 0.0);
        core::requireValue(box.blur >= 0 && box.blur <= 100, b, "blur", "must be 0..100 [px]");
        room.boxes.push_back(std::move(box));
    }
}

void loadRoom(const std::string& path, RoomSpec& room) {
    core::namingSource(path, [&] { readRoom(path, room); });
}

PersonSpec loadPerson(const mrpt::config::CConfigFileBase& cfg, const std::string& s,
                      const std::string& path) {
    core::requireKnownKeys(cfg, s,
                           {"kind", "texture", "height", "path", "speed", "start_offset", "base_z",
                            "sway_deg", "sway_period", "sway_pivot", "bob", "gesture_deg",
                            "gesture_period", "gesture_region", "gesture_pivot"});
    // (no source: loadScenario's namingSource names the file, "with --set" where it applies)
    PersonSpec p;
    p.name = s;
    const std::string where = path + " [" + s + "]";
    try {
        p.kind = parsePersonKind(requiredText(cfg, s, "kind"));
    } catch (const std::invalid_argument& e) {
        const std::string m = e.what();
        if (m.rfind('[', 0) == 0) throw;  // requiredText's own: "[section] key: missing"
        throw std::invalid_argument("[" + s + "] kind: " + m);  // the file is added to "[..."
    }
    // Keys of the other kind were ignored without a word (sway_deg = 20 on a walker, speed
    // on a sitter: byte-identical renders); refused, as the detector refuses another
    // type's keys.
    {
        const bool walks = p.kind == PersonKind::Walking;
        const std::vector<std::string> other =
            walks ? std::vector<std::string>{"sway_deg", "sway_period", "sway_pivot"}
                  : std::vector<std::string>{"speed", "start_offset", "bob"};
        for (const auto& k : other)
            core::requireValue(!cfg.keyExists(s, k), s, k,
                               "is not used by a " + toString(p.kind) + " person (" +
                                   (walks ? "sway_* are for sitting and standing people"
                                          : "speed, start_offset and bob are for walkers") +
                                   "): remove it");
    }
    const auto tex =
        resolveImages(requiredText(cfg, s, "texture"), dirOf(path), where + " texture");
    if (tex.size() != 1) throw std::invalid_argument(where + " texture: need exactly one file");
    p.texture = tex.front();
    // Read now, so that an image without alpha or one that does not decode is named by its
    // file, section and key (the renderer, which reads it again, knew only the image).
    try {
        (void)loadPersonTexture(p.texture);
    } catch (const std::exception& e) {
        throw std::invalid_argument("[" + s + "] texture: " + e.what());  // the file is added
    }
    p.height = core::readDouble(cfg, s, "height", p.height);
    p.speed = core::readDouble(cfg, s, "speed", p.speed);
    p.start_offset = core::readDouble(cfg, s, "start_offset", p.start_offset);
    p.base_z = core::readDouble(cfg, s, "base_z", p.base_z);
    p.sway_deg = core::readDouble(cfg, s, "sway_deg", p.sway_deg);
    p.sway_period = core::readDouble(cfg, s, "sway_period", p.sway_period);
    p.sway_pivot = core::readDouble(cfg, s, "sway_pivot", p.sway_pivot);
    p.bob = core::readDouble(cfg, s, "bob", p.bob);
    p.gesture_deg = core::readDouble(cfg, s, "gesture_deg", p.gesture_deg);
    p.gesture_period = core::readDouble(cfg, s, "gesture_period", p.gesture_period);
    // Required for a gesture; checked whenever given (a person stilled with --set
    // gesture_deg=0 keeps the file's, and a bad one went unnoticed until gesture_deg was set).
    const auto unit = [](double v) { return v >= 0 && v <= 1; };
    if (p.gestures() || cfg.keyExists(s, "gesture_region")) {
        const auto r = core::parseNumberList(requiredText(cfg, s, "gesture_region"),
                                             where + " gesture_region", 4);
        p.gesture_region = {r[0], r[1], r[2], r[3]};
        core::requireValue(
            unit(r[0]) && unit(r[1]) && unit(r[2]) && unit(r[3]) && r[0] < r[2] && r[1] < r[3], s,
            "gesture_region",
            "must be [left top right bottom], fractions of the photo in [0, 1] "
            "with left < right and top < bottom");
    }
    if (p.gestures() || cfg.keyExists(s, "gesture_pivot")) {
        const auto c = core::parseNumberList(requiredText(cfg, s, "gesture_pivot"),
                                             where + " gesture_pivot", 2);
        p.gesture_pivot = {c[0], c[1]};
        core::requireValue(unit(c[0]) && unit(c[1]), s, "gesture_pivot",
                           "must be [across down], fractions of the photo in [0, 1]");
    }
    const auto xy = core::parseNumberList(requiredText(cfg, s, "path"), where + " path");
    if (xy.size() < 2 || xy.size() % 2)
        throw std::invalid_argument(where + " path: need x y pairs");
    for (std::size_t i = 0; i < xy.size(); i += 2) p.path.emplace_back(xy[i], xy[i + 1]);
    core::requireValue(p.height > 0.2 && p.height < 3.0, s, "height", "must be in (0.2, 3) [m]");
    core::requireValue(p.speed >= 0 && p.speed < 5, s, "speed", "must be in [0, 5) [m/s]");
    // As the camera's periods: 1e-7 s made a sitter jump about from frame to frame while
    // labelled static; a walker 1e300 m along its path stood still while labelled moving.
    core::requireValue(p.sway_period >= 0.1 && p.sway_period <= 1e5, s, "sway_period",
                       "must be in [0.1, 1e5] [s]");
    core::requireValue(std::abs(p.start_offset) <= 1e4, s, "start_offset",
                       "must be in [-1e4, 1e4] [m]");
    // (A person bobbing 1e9 m, or swaying over, rendered without a word.)
    core::requireValue(std::abs(p.sway_deg) <= 45, s, "sway_deg", "must be in [-45, 45] [deg]");
    core::requireValue(p.bob >= 0 && p.bob <= 0.3, s, "bob", "must be in [0, 0.3] [m]");
    core::requireValue(std::abs(p.gesture_deg) <= 90, s, "gesture_deg",
                       "must be in [-90, 90] [deg]");
    core::requireValue(p.gesture_period >= 0.1 && p.gesture_period <= 1e5, s, "gesture_period",
                       "must be in [0.1, 1e5] [s]");
    core::requireValue(p.sway_pivot >= 0 && p.sway_pivot <= p.height, s, "sway_pivot",
                       "must be in [0, height] [m]");
    if (p.kind == PersonKind::Walking)
        core::requireValue(p.path.size() >= 2 && pathLength(p.path) > 0.1, s, "path",
                           "a walker needs at least two points 0.1 m apart");
    else  // (the points after the first were ignored)
        core::requireValue(
            p.path.size() == 1, s, "path",
            "a " + toString(p.kind) + " person stays at one point: give one x y pair");
    return p;
}

}  // namespace

namespace {

Scenario readScenario(const std::string& path, const std::vector<std::string>& overrides) {
    const auto cfg = core::loadIni(path);
    core::applyOverrides(*cfg, overrides, "--set");
    Scenario sc;
    sc.source = path;
    sc.overrides = overrides;
    const std::string s = "scenario";
    core::requireKnownKeys(
        *cfg, s,
        {"name", "room", "duration", "n_frames", "rate_hz", "t0", "seed", "rgb_noise_sigma",
         "near_clip", "far_clip", "texture_filter", "room_set"});  // (named by namingSource)
    sc.name = cfg->read_string(s, "name", fs::path(path).stem().string());
    core::requireValue(!sc.name.empty() && sc.name.find('/') == std::string::npos &&
                           sc.name != "." && sc.name != "..",
                       s, "name",
                       "must be a non-empty name without '/', not '.' or '..' (it names the "
                       "output folder)");
    sc.rate_hz = core::readDouble(*cfg, s, "rate_hz", sc.rate_hz);
    // Stamps and file names are written with 6 decimals: below 1 Hz frames are far apart
    // (1e-300 Hz gave 300-digit stamps).
    core::requireValue(sc.rate_hz >= 1 && sc.rate_hz <= 1000, "scenario", "rate_hz",
                       "must be in [1, 1000] [Hz]");
    const double duration = core::readDouble(*cfg, s, "duration", 0.0);
    const int n = core::readInt(*cfg, s, "n_frames", 0);
    core::requireValue(!cfg->keyExists(s, "duration") || duration > 0, s, "duration",
                       "must be > 0 [s]");
    core::requireValue(!cfg->keyExists(s, "n_frames") || n > 0, s, "n_frames", "must be >= 1");
    if ((duration > 0) == (n > 0))
        throw std::invalid_argument(
            path + " [scenario]: give exactly one of 'duration' [s] or 'n_frames'");
    // A sequence is minutes long: a billion frames started a render of days.
    core::requireValue(
        n <= kMaxFrames, s, "n_frames",
        "must be at most " + std::to_string(kMaxFrames) + " (" + std::to_string(n) + " given)");
    core::requireValue(duration * sc.rate_hz <= kMaxFrames + 0.5, s, "duration",
                       "gives more than " + std::to_string(kMaxFrames) +
                           " frames at rate_hz (duration * rate_hz)");
    sc.n_frames = n > 0 ? std::size_t(n) : std::size_t(std::lround(duration * sc.rate_hz));
    core::requireValue(sc.n_frames > 0, s, "duration",
                       "gives no frame at rate_hz (at least one: duration >= 0.5 / rate_hz)");
    sc.t0 = core::readDouble(*cfg, s, "t0", sc.t0);
    // Beyond 1e10 s a frame's 1 / rate_hz is lost in the double: frames got one stamp, one
    // file name, and overwrote each other.
    core::requireValue(sc.t0 >= 0 && sc.t0 <= 1e10, s, "t0", "must be in [0, 1e10] [s]");
    sc.seed = core::readUint64(*cfg, s, "seed", sc.seed);
    sc.rgb_noise_sigma = core::readDouble(*cfg, s, "rgb_noise_sigma", sc.rgb_noise_sigma);
    sc.near_clip = core::readDouble(*cfg, s, "near_clip", sc.near_clip);
    sc.far_clip = core::readDouble(*cfg, s, "far_clip", sc.far_clip);
    const std::string filter = cfg->read_string(s, "texture_filter", "linear");
    core::requireValue(filter == "linear" || filter == "nearest", s, "texture_filter",
                       "must be linear or nearest, got '" + filter + "'");
    sc.texture_linear = filter == "linear";
    // (1e300 became an infinite float std: frames of saturated noise, without a word.)
    core::requireValue(sc.rgb_noise_sigma >= 0 && sc.rgb_noise_sigma <= 255, "scenario",
                       "rgb_noise_sigma", "must be in [0, 255] [grey levels]");
    core::requireValue(sc.near_clip > 0 && sc.far_clip > sc.near_clip, "scenario", "far_clip",
                       "need 0 < near_clip < far_clip [m]");
    // The depth read back from GL loses precision as near_clip shrinks (0.001 m: depth 4 cm
    // off at 3 m, person pixels lost from the truth), and a far_clip past a float's range
    // (4e38) rendered no depth and no person at all; both without a word.
    core::requireValue(sc.near_clip >= 0.01, "scenario", "near_clip",
                       "must be >= 0.01 [m] (below, the rendered depth loses its precision)");
    core::requireValue(sc.far_clip <= 1e4, "scenario", "far_clip", "must be <= 1e4 [m]");

    sc.K = cfg->sectionExists("camera") ? core::CameraIntrinsics::fromConfig(*cfg, "camera")
                                        : core::CameraIntrinsics::fromPreset("freiburg3");
    core::requireValue(sc.K.width >= 8 && sc.K.height >= 8, "camera", "width/height",
                       "must be at least 8 px (the renderer's smallest image)");
    for (double d : sc.K.dist)
        if (d != 0.0)
            throw std::invalid_argument(path +
                                        " [camera]: the renderer is a pinhole, 'dist' must be 0");

    std::string room = requiredText(*cfg, s, "room");
    if (fs::path(room).is_relative())
        room = (fs::path(dirOf(path)) / room).lexically_normal().string();
    sc.room.overrides =
        core::overrideItems(cfg->read_string(s, "room_set", ""), path + " [" + s + "] room_set");
    if (!fs::is_regular_file(room))
        throw std::invalid_argument(path + " [scenario] room: '" + room + "' " +
                                    (fs::is_directory(room) ? "is a folder, not a room file"
                                     : fs::exists(room)     ? "is no regular file"
                                                            : "is no such file"));
    try {
        loadRoom(room, sc.room);
    } catch (const std::invalid_argument& e) {
        if (sc.room.overrides.empty()) throw;
        throw std::invalid_argument(std::string(e.what()) + " (room_set of " + path + ")");
    }

    if (cfg->sectionExists("trajectory")) sc.trajectory.loadFromConfig(*cfg, "trajectory");
    if (cfg->sectionExists("depth_noise")) sc.depth_noise.loadFromConfig(*cfg, "depth_noise");
    for (const auto& p : sectionsWithPrefix(*cfg, "person_")) {
        if (p.size() <= std::string("person_").size())
            throw std::invalid_argument("[" + p +
                                        "]: a person's section needs a name after "
                                        "'person_'");
        sc.people.push_back(loadPerson(*cfg, p, path));
    }
    // The label images hold a person's id in 8 bits, 0 for no one: person 256 was written as 0.
    if (sc.people.size() > 255)
        throw std::invalid_argument(path + ": " + std::to_string(sc.people.size()) +
                                    " [person_*] sections; at most 255");
    // A TUM depth PNG (and the rawlog) holds 16 bits of 1/5000 m: at most 13.1 m. Deeper
    // depth failed the render at its first far frame, after the old outputs were gone.
    constexpr double kMaxDepth = 65535.0 / 5000.0;
    if (sc.depth_noise.enabled) {
        core::requireValue(sc.depth_noise.max_range <= kMaxDepth, "depth_noise", "max_range",
                           "must be at most 13.107 m (16-bit TUM depth at 5000 per metre)");
    } else {
        const double deepest = std::min(sc.far_clip, sc.room.size.norm());
        core::requireValue(deepest <= kMaxDepth, "scenario", "far_clip",
                           "with [depth_noise] enabled = false the depth reaches " +
                               std::to_string(deepest) +
                               " m (far_clip or the room's diagonal); a TUM depth PNG holds at "
                               "most 13.107 m: lower far_clip");
    }
    // The camera and the people inside the room: outside it they rendered walls seen from
    // behind, or nobody, without a word.
    const auto& R = sc.room.size;
    const auto inRoom = [&](double x, double y) {
        return x > 0 && x < R.x() && y > 0 && y < R.y();
    };
    const auto where = [&](double x, double y) {
        std::ostringstream m;
        m << "(" << x << ", " << y << ") lies outside the room (0.." << R.x() << " x 0.." << R.y()
          << " m)";
        return m.str();
    };
    for (std::size_t k = 0; k < sc.people.size(); ++k) {
        for (const auto& q : sc.people[k].path)
            core::requireValue(inRoom(q.x(), q.y()), sc.people[k].name, "path",
                               "the point " + where(q.x(), q.y()));
        // Sunk through the floor or lifted over the ceiling (base_z -100, 1e9): nobody.
        const auto& p = sc.people[k];
        std::ostringstream m;
        m << "must be in (-height, room height) = (" << -p.height << ", " << R.z()
          << ") [m]: the person is under the floor or over the ceiling";
        core::requireValue(p.base_z > -p.height && p.base_z < R.z(), p.name, "base_z", m.str());
    }
    // Every frame (a few microseconds each): a sample of them let a short excursion through
    // on a long scenario.
    for (std::size_t i = 0; i < sc.n_frames; ++i) {
        const auto T = cameraPoseAt(sc.trajectory, sc.elapsed(i));
        if (inRoom(T.x(), T.y()) && T.z() > 0 && T.z() < R.z()) continue;
        std::ostringstream m;
        m << "the camera at t = " << sc.elapsed(i) << " s is at (" << T.x() << ", " << T.y() << ", "
          << T.z() << "), outside " << roomExtent(R);
        core::requireValue(false, "trajectory", "position", m.str());
    }

    const std::string source = overrides.empty() ? path : path + " with --set";
    // The room's sections belong to the room file (--set room.wall_blur=3 was "unknown
    // section [room]", which did not say where it goes).
    auto room_sections = sectionsWithPrefix(*cfg, "box_");
    if (cfg->sectionExists("room")) room_sections.insert(room_sections.begin(), "room");
    for (const auto& r : room_sections)
        throw std::invalid_argument(source + ": [" + r +
                                    "] is a section of the room file; the scenario sets it with "
                                    "[scenario] room_set (--set \"scenario.room_set=" +
                                    r + ".KEY=VALUE\")");
    core::requireKnownSections(
        *cfg, {"scenario", "camera", "trajectory", "depth_noise", "person_*"}, source);
    return sc;
}

}  // namespace

Scenario loadScenario(const std::string& path, const std::vector<std::string>& overrides) {
    // As devslam-run says it: a key --set wrote is not blamed on the file alone.
    return core::namingSource(overrides.empty() ? path : path + " with --set",
                              [&] { return readScenario(path, overrides); });
}

}  // namespace devslam::render
