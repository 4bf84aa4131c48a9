#include <devslam/eval/MaskScore.h>

#include <devslam/core/Picture.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace devslam::eval {

std::map<std::string, std::vector<PersonEntry>> readPersons(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open '" + path + "'");
    std::map<std::string, std::vector<PersonEntry>> out;
    std::map<std::string, int> first_line;  // "stamp id" -> its line
    std::string line;
    for (int n = 1; std::getline(in, line); ++n) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream ss(line);
        std::string t, state;
        PersonEntry p;
        int x = 0, y = 0, w = 0, h = 0;
        const auto where = path + " line " + std::to_string(n) + ": ";
        if (!(ss >> t >> p.id >> p.name >> state >> x >> y >> w >> h >> p.visible_pixels) ||
            (state != "moving" && state != "static"))
            throw std::runtime_error(
                where + "expected 'timestamp id name moving|static x y w h visible_pixels'");
        if (std::string extra; ss >> extra)
            throw std::runtime_error(where + "'" + extra + "' after the 9 values");
        // Label images are 8-bit, 0 the background: another id labels no pixel.
        if (p.id < 1 || p.id > 255)
            throw std::runtime_error(where + "person id " + std::to_string(p.id) +
                                     " (the labels are 8-bit: 1..255)");
        if (w < 0 || h < 0 || p.visible_pixels < 0)
            throw std::runtime_error(where + "a negative box size or visible_pixels");
        // A person listed twice in a frame was scored twice (a duplicated line: 6 -> 7
        // person-frames, without a word).
        if (const auto [it, fresh] = first_line.emplace(t + " " + std::to_string(p.id), n); !fresh)
            throw std::runtime_error(where + "person " + std::to_string(p.id) + " of frame " + t +
                                     " again (line " + std::to_string(it->second) + ")");
        p.moving = state == "moving";
        out[t].push_back(p);
    }
    return out;
}

void MaskScore::add(const cv::Mat& mask, const cv::Mat& labels,
                    const std::vector<PersonEntry>& persons, int min_pixels, double timestamp,
                    const std::vector<FilterBox>& boxes) {
    const bool has_mask = !mask.empty();
    if (has_mask) masked_px += cv::countNonZero(mask);
    for (const auto& p : persons) {
        const cv::Mat mine = labels == p.id;
        const double vis = cv::countNonZero(mine);
        const double hit = has_mask ? cv::countNonZero(mine & mask) : 0.0;
        if (p.moving) {
            moving_px += vis;
            moving_px_masked += hit;
        }
        if (vis < min_pixels) continue;
        const bool masked = hit >= 0.5 * vis;
        if (masked != p.moving) {
            Error e{timestamp, p.id, p.moving, static_cast<int>(vis), hit / vis};
            const cv::Rect frame(0, 0, labels.cols, labels.rows);
            for (const auto& b : boxes) {
                const cv::Rect r = cv::Rect(b.box) & frame;
                if (r.empty()) continue;
                const double cover = cv::countNonZero(mine(r)) / vis;
                if (cover >= min_box_cover && cover > e.box_cover) {
                    e.box_cover = cover;
                    e.filter_box = b.state;
                }
            }
            errors.push_back(std::move(e));
        }
        if (p.moving) {
            ++moving_instances;
            moving_masked += masked;
        } else {
            ++static_instances;
            static_masked += masked;
        }
    }
}

std::size_t MaskScore::movingMissedWithoutBox() const {
    std::size_t n = 0;
    for (const auto& e : errors) n += e.moving && e.filter_box == "none" ? 1 : 0;
    return n;
}

double MaskScore::movingRecall() const {
    return moving_instances ? double(moving_masked) / moving_instances : 0.0;
}
double MaskScore::staticMasked() const {
    return static_instances ? double(static_masked) / static_instances : 0.0;
}
double MaskScore::movingAreaRecall() const {
    return moving_px > 0 ? moving_px_masked / moving_px : 0.0;
}
double MaskScore::precision() const {
    return masked_px > 0 ? moving_px_masked / masked_px : 0.0;
}

bool PersonTruth::available(const std::string& folder) {
    namespace fs = std::filesystem;
    // Both parts of the truth are needed (devslam-synth --no-labels writes persons.txt only).
    return fs::is_directory(folder) && fs::exists(fs::path(folder) / "persons.txt") &&
           fs::is_directory(fs::path(folder) / "labels");
}

bool PersonTruth::hasWalkers(const std::string& folder) {
    if (!available(folder)) return false;
    for (const auto& [stamp, persons] :
         readPersons((std::filesystem::path(folder) / "persons.txt").string()))
        for (const auto& p : persons)
            if (p.moving) return true;
    return false;
}

std::optional<PersonTruth> PersonTruth::open(const std::string& folder) {
    if (!available(folder)) return std::nullopt;
    PersonTruth t;
    t.folder_ = folder;
    t.persons_ = readPersons((std::filesystem::path(folder) / "persons.txt").string());
    return t;
}

PersonTruth::FrameTruth PersonTruth::frame(double timestamp, cv::Size expected) const {
    char stamp[64];
    std::snprintf(stamp, sizeof stamp, "%.6f", timestamp);
    const auto it = persons_.find(stamp);
    if (it == persons_.end())
        throw MissingTruth(folder_ + "/persons.txt: no entry for frame " + stamp);
    const std::string label_path = folder_ + "/labels/" + stamp + ".png";
    FrameTruth f;
    std::string why;
    f.labels = core::readImage(label_path, cv::IMREAD_UNCHANGED, why);
    if (f.labels.empty() || f.labels.type() != CV_8UC1)
        throw MissingTruth("cannot read person labels '" + label_path +
                           "' (expected an 8-bit one-channel PNG)" + why);
    if (!expected.empty() && f.labels.size() != expected)  // unusable, as a missing one
        throw MissingTruth("person labels '" + label_path + "' are " +
                           std::to_string(f.labels.cols) + "x" + std::to_string(f.labels.rows) +
                           ", the frame is " + std::to_string(expected.width) + "x" +
                           std::to_string(expected.height));
    // Every labelled id is a person of this frame's rows (devslam-synth lists every person in
    // every frame): another render's labels, or a hand-edited persons.txt, were scored against
    // the wrong people without a word. Unusable truth, as a missing label image: the run ends
    // there and keeps the frames before.
    int hist[256] = {};
    for (int r = 0; r < f.labels.rows; ++r) {
        const uchar* row = f.labels.ptr<uchar>(r);
        for (int c = 0; c < f.labels.cols; ++c) ++hist[row[c]];
    }
    for (int id = 1; id < 256; ++id)
        if (hist[id] > 0 && std::none_of(it->second.begin(), it->second.end(),
                                         [&](const PersonEntry& p) { return p.id == id; }))
            throw MissingTruth("person labels '" + label_path + "' hold id " +
                                     std::to_string(id) + ", which " + folder_ +
                                     "/persons.txt does not list for frame " + stamp +
                                     " (labels of another render?)");
    f.persons = &it->second;
    return f;
}

void PersonTruth::score(const cv::Mat& mask, double timestamp, int min_pixels, MaskScore& score,
                        const std::vector<FilterBox>& boxes) const {
    const auto f = frame(timestamp, mask.size());
    score.add(mask, f.labels, *f.persons, min_pixels, timestamp, boxes);
}

cv::Mat PersonTruth::walkerMask(double timestamp, int margin, cv::Size frame_size) const {
    const auto f = frame(timestamp, frame_size);
    cv::Mat mask = cv::Mat::zeros(f.labels.size(), CV_8UC1);
    for (const auto& p : *f.persons)
        if (p.moving) mask |= f.labels == p.id;
    if (margin > 0)
        cv::dilate(
            mask, mask,
            cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * margin + 1, 2 * margin + 1)));
    return mask;
}

}  // namespace devslam::eval
