#include <devslam/eval/Plot.h>
#include <devslam/eval/Report.h>

#include <devslam/core/Picture.h>
#include <devslam/core/Results.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace devslam::eval {

namespace {

std::string fmt(const char* f, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, f, v);
    return buf;
}

/// A JSON number; JSON has none for nan and inf (printed as "-nan", the file was invalid).
std::string num(double v) {
    if (!std::isfinite(v)) return "null";
    std::ostringstream o;
    o.precision(9);
    o << v;
    return o.str();
}

std::string summaryJson(const core::Summary& s) {
    std::ostringstream o;
    o << "{\"count\": " << s.count << ", \"rmse\": " << num(s.rmse) << ", \"mean\": "
      << num(s.mean) << ", \"median\": " << num(s.median) << ", \"std\": " << num(s.std)
      << ", \"min\": " << num(s.min) << ", \"max\": " << num(s.max) << "}";
    return o.str();
}

std::string deltaText(const RpeOptions* o) {
    if (!o) return "";
    return fmt("%g", o->delta) + (o->delta_in_frames ? " frames" : " s");
}

}  // namespace

std::string formatTable(const AteResult* ate, const RpeResult* rpe, const RpeOptions* ro) {
    std::ostringstream o;
    auto row = [&](const std::string& name, const core::Summary& s, const char* unit, double k) {
        char buf[200];
        std::snprintf(buf, sizeof buf, "%-22s %10.6f %10.6f %10.6f %10.6f %10.6f %10.6f  %s\n",
                      name.c_str(), k * s.rmse, k * s.mean, k * s.median, k * s.std, k * s.min,
                      k * s.max, unit);
        o << buf;
    };
    char head[200];
    std::snprintf(head, sizeof head, "%-22s %10s %10s %10s %10s %10s %10s\n", "metric", "rmse",
                  "mean", "median", "std", "min", "max");
    o << head;
    if (ate) {
        row("ATE translation", ate->trans, "m", 1.0);
        o << "  (" << ate->trans.count << " pairs of " << ate->n_est << " estimated and "
          << ate->n_gt << " ground-truth poses)\n";
    }
    if (rpe) {
        const std::string d = ro ? " (" + deltaText(ro) + ")" : "";
        row("RPE translation" + d, rpe->trans, "m", 1.0);
        row("RPE rotation" + d, rpe->rot, "deg", 1.0);
        o << "  (" << rpe->n_pairs << " pose pairs)\n";
    }
    return o.str();
}

std::string toJson(const AteResult* ate, const RpeResult* rpe, const RpeOptions* ro) {
    std::ostringstream o;
    o << "{";
    if (ate) {
        o << "\"ate\": {\"translation_m\": " << summaryJson(ate->trans)
          << ", \"n_est\": " << ate->n_est << ", \"n_gt\": " << ate->n_gt << "}";
    }
    if (rpe) {
        if (ate) o << ", ";
        o << "\"rpe\": {";
        if (ro)
            o << "\"delta\": " << num(ro->delta) << ", \"delta_unit\": \""
              << (ro->delta_in_frames ? "f" : "s") << "\", ";
        o << "\"translation_m\": " << summaryJson(rpe->trans)
          << ", \"rotation_deg\": " << summaryJson(rpe->rot) << ", \"pairs\": " << rpe->n_pairs
          << "}";
    }
    o << "}\n";
    return o.str();
}

void writeJson(const std::string& path, const AteResult* ate, const RpeResult* rpe,
               const RpeOptions* ro) {
    // Whole or not at all: a full disk left an empty file in place of the earlier one.
    core::writeFileWhole(path, toJson(ate, rpe, ro));
}

void plotAte(const std::string& path, const AteResult& ate, const std::string& title) {
    // The title (often a file path) gets a band of its own across the figure, so that it
    // runs into no plot; the plots below it have short titles.
    constexpr int kBand = 32, kWidth = 1200;
    cv::Mat canvas(kBand + 900, kWidth, CV_8UC3, cv::Scalar(255, 255, 255));
    drawTitle(canvas, title + ", ATE RMSE " + fmt("%.4f", ate.trans.rmse) + " m", {10, 22},
              kWidth - 20, 0.6);
    std::vector<double> gx, gy, ex, ey, t;
    for (std::size_t i = 0; i < ate.gt_xyz.size(); ++i) {
        gx.push_back(ate.gt_xyz[i].x()), gy.push_back(ate.gt_xyz[i].y());
        ex.push_back(ate.est_xyz[i].x()), ey.push_back(ate.est_xyz[i].y());
        t.push_back(ate.stamps[i] - ate.stamps.front());
    }
    const double emax = std::max(ate.trans.max, 1e-9);
    std::vector<cv::Scalar> colours;
    for (double e : ate.errors) colours.push_back(heatColour(e / emax));

    Plot top(cv::Rect(0, kBand, 600, 900), "top view", "x [m]", "y [m]");
    top.fit(gx, gy);
    top.fit(ex, ey);
    top.equalAspect();
    top.axes(canvas);
    top.line(canvas, gx, gy, cv::Scalar(0, 0, 0), 2);
    for (std::size_t i = 0; i < gx.size(); ++i)  // error segments gt -> estimate
        cv::line(canvas, top.toPixel(gx[i], gy[i]), top.toPixel(ex[i], ey[i]), colours[i], 1,
                 cv::LINE_AA);
    top.points(canvas, ex, ey, colours, 3);
    std::vector<double> all_x = gx, all_y = gy;  // the legend avoids both trajectories
    all_x.insert(all_x.end(), ex.begin(), ex.end());
    all_y.insert(all_y.end(), ey.begin(), ey.end());
    top.legend(canvas,
               {{"ground truth", cv::Scalar(0, 0, 0)},
                {"estimate (blue 0 -> red " + fmt("%.4f", emax) + " m)", heatColour(1.0)}},
               all_x, all_y);

    const char* names[3] = {"x", "y", "z"};
    for (int a = 0; a < 3; ++a) {
        std::vector<double> g, e;
        for (std::size_t i = 0; i < ate.gt_xyz.size(); ++i)
            g.push_back(ate.gt_xyz[i][a]), e.push_back(ate.est_xyz[i][a]);
        Plot p(cv::Rect(600, kBand + 300 * a, 600, 300),
               std::string(names[a]) + " over time: truth black, estimate orange", "t [s]",
               std::string(names[a]) + " [m]");
        p.fit(t, g);
        p.fit(t, e);
        p.axes(canvas);
        p.line(canvas, t, g, cv::Scalar(0, 0, 0), 2);
        p.line(canvas, t, e, cv::Scalar(30, 120, 255), 1);
    }
    // Whole or not at all (two runs writing one plot at once spliced their PNGs), and an
    // error says why (cv::imwrite did not).
    try {
        core::writePngWhole(path, canvas);
    } catch (const std::exception& e) {  // "cannot write 'PATH': why"
        throw std::runtime_error(std::string("plot: ") + e.what());
    }
}

}  // namespace devslam::eval
