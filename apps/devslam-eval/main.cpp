// devslam-eval: ATE and RPE of an estimated trajectory against ground truth, computed as
// the TUM RGB-D benchmark tools do (evaluate_ate.py, evaluate_rpe.py --fixed_delta).
#include <devslam/core/Interrupt.h>
#include <devslam/core/Parse.h>
#include <devslam/core/Results.h>
#include <devslam/eval/Metrics.h>
#include <devslam/eval/Report.h>
#include <devslam/io/TrajectoryIO.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace {

const char* kUsage = R"(usage: devslam-eval GROUNDTRUTH ESTIMATE [options]
  Both files in TUM format: 'timestamp tx ty tz qx qy qz qw' per line, '#' comments.
options:
  --max-dt S        association window [s] (default 0.02, as associate.py)
  --offset S        time offset added to the estimate [s] (default 0)
  --scale K         scale applied to the estimate's translations (default 1, 1e-6..1e6)
  --delta D         RPE interval (default 1)
  --delta-unit U    s (seconds, default) or f (frames)
  --json FILE       also write the figures as JSON
  --plot FILE.png   also write a plot (top view coloured by error, x/y/z over time)
  --title TEXT      plot title (default: the estimate's file name)
  --no-rpe          ATE only
)";

/// A finite number (core::parseNumber refuses "nan" and "inf"); `positive`: also > 0.
double number(const std::string& opt, const std::string& v, bool positive = false) {
    const double x = devslam::core::parseNumber(v, opt);
    if (positive && !(x > 0))
        throw std::invalid_argument(opt + ": must be > 0, got '" + v + "'");
    return x;
}

}  // namespace

static int appMain(int argc, char** argv) {
    try {
        std::vector<std::string> pos;
        devslam::eval::AteOptions ao;
        devslam::eval::RpeOptions ro;
        std::string json, plot, title;
        bool rpe = true;
        devslam::core::refuseRepeatedOptions(argc, argv);
        for (int i = 1; i < argc; ++i) {
            const std::string a = argv[i];
            auto value = [&] { return devslam::core::optionValue(argc, argv, i); };
            if (a == "-h" || a == "--help") {
                std::cout << kUsage;
                return 0;
            } else if (a == "--max-dt")
                ao.max_dt = number(a, value(), true);
            else if (a == "--offset")
                ao.offset = ro.offset = number(a, value());
            else if (a == "--scale") {
                ao.scale = number(a, value(), true);
                // 1e308 overflowed the alignment (an rmse of -nan, under exit status 0).
                if (ao.scale < devslam::eval::kMinScale || ao.scale > devslam::eval::kMaxScale)
                    throw std::invalid_argument("--scale: must be in [1e-6, 1e6], got '" +
                                                std::string(argv[i]) + "'");
            }
            else if (a == "--delta")
                ro.delta = number(a, value(), true);
            else if (a == "--delta-unit") {
                const std::string u = value();
                if (u != "s" && u != "f")
                    throw std::invalid_argument("--delta-unit: 's' or 'f', got '" + u + "'");
                ro.delta_in_frames = (u == "f");
            } else if (a == "--json" || a == "--plot") {
                std::string& out = a == "--json" ? json : plot;
                out = value();
                // (an empty one, a script's unset variable, wrote nothing and said nothing)
                if (out.empty()) throw std::invalid_argument(a + ": the file name is empty");
            } else if (a == "--title")
                title = value();
            else if (a == "--no-rpe")
                rpe = false;
            else if (!a.empty() && a[0] == '-')
                throw std::invalid_argument("unknown option " + a);
            else
                pos.push_back(a);
        }
        if (pos.size() != 2) {  // (the usage alone did not say what was wrong)
            std::cerr << "devslam-eval: expected two files, GROUNDTRUTH and ESTIMATE, got "
                      << pos.size()
                      << (pos.size() > 2 ? " (the third: '" + pos[2] + "')" : std::string()) << "\n"
                      << kUsage;
            return 2;
        }
        // Before the inputs are read (it came after the ATE, with a hint that did not fit).
        if (ro.delta_in_frames && ro.delta != std::floor(ro.delta)) {
            std::ostringstream m;
            m << "--delta: in frames (--delta-unit f) a whole number, got " << ro.delta;
            throw std::invalid_argument(m.str());
        }
        if (!plot.empty() && !devslam::core::endsWithNoCase(plot, ".png"))
            throw std::invalid_argument("--plot '" + plot + "': the plot's name must end in .png");
        // The outputs are written after the inputs are read: one that is an input (--json
        // EST) replaced the estimate with the figures.
        for (const auto& [opt, out] : {std::pair{"--json", json}, {"--plot", plot}})
            for (const auto& in : pos) {
                if (!out.empty() && devslam::core::sameFile(in, out))
                    throw std::invalid_argument(std::string(opt) + " '" + out +
                                                "' is the input '" + in +
                                                "': writing it would destroy it; name another");
            }
        // Both outputs in one file: the plot replaced the JSON, and the command said 0.
        if (!json.empty() && !plot.empty() &&
            (std::filesystem::weakly_canonical(json) == std::filesystem::weakly_canonical(plot) ||
             devslam::core::sameFile(json, plot)))
            throw std::invalid_argument("--json and --plot are the same file '" + plot +
                                        "': the plot would replace the figures; name two");
        const auto gt = devslam::io::readTumTrajectory(pos[0]);
        auto est = devslam::io::readTumTrajectory(pos[1]);
        const auto ate = devslam::eval::computeAte(gt, est, ao);
        std::optional<devslam::eval::RpeResult> r;
        std::string rpe_error;  // the ATE stands without it: written, then the error said
        if (rpe) {
            if (ao.scale != 1.0)
                for (auto& p : est)
                    p.pose.setFromValues(ao.scale * p.pose.x(), ao.scale * p.pose.y(),
                                         ao.scale * p.pose.z(), p.pose.yaw(), p.pose.pitch(),
                                         p.pose.roll());
            try {
                r = devslam::eval::computeRpe(gt, est, ro);
            } catch (const std::invalid_argument& e) {
                rpe_error = e.what();
            }
        }
        std::cout << devslam::eval::formatTable(&ate, r ? &*r : nullptr, &ro);
        if (!json.empty()) devslam::eval::writeJson(json, &ate, r ? &*r : nullptr, &ro);
        if (!plot.empty()) devslam::eval::plotAte(plot, ate, title.empty() ? pos[1] : title);
        if (!rpe_error.empty()) {
            std::cerr << "devslam-eval: " << rpe_error
                      << "\ndevslam-eval: the ATE above is written; for the RPE of a short "
                         "run use a smaller --delta (or --delta-unit f), or --no-rpe\n";
            return 1;
        }
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "devslam-eval: " << e.what() << "\n";
        return 1;
    }
}

int main(int argc, char** argv) {
    devslam::core::ignoreFileSizeSignal();  // a write past ulimit -f is reported, not a kill
    // The figures go to the standard output: one that cannot be written (a full disk behind
    // '>') lost them while the program said 0.
    return devslam::core::withStandardOutput("devslam-eval", appMain(argc, argv));
}
