#include "RunJson.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>

namespace devslam::bench {

// Written by hand: no dependency reads JSON strictly. MRPT 2.5.8's yaml::FromText (libfyaml)
// reads JSON, but took a run.json cut in the middle of a string for a whole map, printing the
// error and throwing nothing.
std::optional<std::map<std::string, JsonScalar>> jsonScalars(const std::string& js) {
    std::map<std::string, JsonScalar> out;
    std::size_t i = 0;
    const auto ws = [&] {
        while (i < js.size() && std::isspace(static_cast<unsigned char>(js[i]))) ++i;
    };
    // The string that opens at js[i]: its contents into `s`; false when it is not closed.
    const auto str = [&](std::string& s) {
        const std::size_t from = ++i;
        for (; i < js.size() && js[i] != '"'; ++i)
            if (js[i] == '\\') ++i;
        if (i >= js.size()) return false;
        s = js.substr(from, i - from);
        ++i;
        return true;
    };
    // A list of members or elements up to `close`, each read by `item`.
    const auto list = [&](char close, const std::function<bool()>& item) {
        ++i;
        ws();
        if (i < js.size() && js[i] == close) return ++i, true;
        for (;;) {
            if (!item()) return false;
            ws();
            if (i >= js.size()) return false;
            if (js[i] == close) return ++i, true;
            if (js[i++] != ',') return false;
        }
    };
    std::function<bool(const std::string&, bool, int)> value = [&](const std::string& path,
                                                                   bool keep, int depth) {
        ws();
        if (i >= js.size() || depth > 200) return false;
        if (js[i] == '{')
            return list('}', [&] {
                ws();
                std::string key;
                if (i >= js.size() || js[i] != '"' || !str(key)) return false;
                ws();
                if (i >= js.size() || js[i++] != ':') return false;
                return value(path.empty() ? key : path + "." + key, keep, depth + 1);
            });
        if (js[i] == '[') return list(']', [&] { return value(path, false, depth + 1); });
        JsonScalar s;
        if (js[i] == '"') {
            s.string = true;
            if (!str(s.text)) return false;
        } else if (const auto word = [&]() -> const char* {
                       for (const char* w : {"true", "false", "null"})
                           if (js.compare(i, std::strlen(w), w) == 0) return w;
                       return nullptr;
                   }()) {
            s.text = word;
            i += s.text.size();
        } else {
            char* end = nullptr;
            std::strtod(js.c_str() + i, &end);
            if (end == js.c_str() + i) return false;
            s.text = js.substr(i, std::size_t(end - js.c_str()) - i);
            i = std::size_t(end - js.c_str());
        }
        if (keep) out[path] = std::move(s);
        return true;
    };
    if (!value("", true, 0)) return std::nullopt;
    ws();
    if (i != js.size()) return std::nullopt;
    return out;
}

RunFigures readRun(const std::string& json_path) {
    std::ifstream in(json_path);
    RunFigures f;
    if (!in) return f;
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string js = ss.str();
    const auto first = js.find_first_not_of(" \t\r\n");
    const auto scalars =
        first == std::string::npos || js[first] != '{' ? std::nullopt : jsonScalars(js);
    if (!scalars) {
        f.unreadable = json_path + " is not a whole JSON object (empty, cut short or garbage)";
        return f;
    }
    // What devslam-run writes in every run.json, whatever its input.
    for (const char* key : {"median_fps", "mean_fps", "lost_frames", "read_error", "interrupted"})
        if (scalars->count(key) == 0) {
            f.unreadable = json_path + " has no \"" + key + "\" (not a devslam-run run.json?)";
            return f;
        }
    const auto number = [&](const std::string& path) {
        const auto it = scalars->find(path);
        return it == scalars->end() || it->second.string
                   ? std::numeric_limits<double>::quiet_NaN()
                   : std::strtod(it->second.text.c_str(), nullptr);
    };
    f.ate_rmse = number("ate.rmse"), f.ate_mean = number("ate.mean");
    f.ate_median = number("ate.median");
    // RPE over 1 s: translational then rotational.
    f.rpe_t_rmse = number("rpe_1s.trans.rmse"), f.rpe_t_mean = number("rpe_1s.trans.mean");
    f.rpe_t_median = number("rpe_1s.trans.median");
    f.rpe_r_rmse = number("rpe_1s.rot_deg.rmse"), f.rpe_r_mean = number("rpe_1s.rot_deg.mean");
    f.rpe_r_median = number("rpe_1s.rot_deg.median");
    f.fps_median = number("median_fps");
    f.fps_mean = number("mean_fps");
    f.lost = number("lost_frames");
    f.keyframes = number("keyframes"), f.landmarks = number("landmarks");
    f.map_mb = number("map_mb");
    f.moving_recall = number("mask_truth.moving_recall");
    f.moving_area_recall = number("mask_truth.moving_area_recall");
    f.mask_precision = number("mask_truth.precision");
    f.static_masked = number("mask_truth.static_masked");
    f.moving_instances = number("mask_truth.moving_instances");
    f.static_instances = number("mask_truth.static_instances");
    // devslam-run writes 0 for a fraction of no instances; here it is undefined.
    if (f.moving_instances == 0) f.moving_recall = f.moving_area_recall = NAN;
    if (f.static_instances == 0) f.static_masked = NAN;
    // A run that stopped at a frame it could not read, or was interrupted, covers part of
    // the input only.
    const auto none = [&](const char* key) {
        const JsonScalar& s = scalars->at(key);
        return s.string && s.text.empty();
    };
    f.ok = none("read_error") && none("interrupted");
    return f;
}

}  // namespace devslam::bench
