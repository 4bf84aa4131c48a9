#include <devslam/core/Results.h>
#include <devslam/slam/MapFile.h>

#include <opencv2/core/persistence.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace devslam::slam {

namespace {
constexpr const char* kFormat = "devslam-map";
constexpr int kVersion = 1;
constexpr int kKeypointCols = 7;  ///< x y size angle response octave class_id

int asInt(std::int64_t v, const char* what) {
    if (v < 0 || v > std::numeric_limits<int>::max())
        throw std::runtime_error(std::string("saveMap: ") + what + " " + std::to_string(v) +
                                 " does not fit the file's 32-bit ids");
    return static_cast<int>(v);
}

/// `fs << key << m`, but an empty matrix as an empty sequence: OpenCV 4.6's base64 writer
/// asserts on an empty array.
void put(cv::FileStorage& fs, const char* key, const cv::Mat& m) {
    fs << key;
    if (m.empty())
        fs << "["
           << "]";
    else
        fs << m;
}

/// One value per row, as a column matrix (every array of the file is a checked matrix).
template <typename T>
cv::Mat column(const std::vector<T>& v, int type) {
    cv::Mat m(static_cast<int>(v.size()), 1, type);
    for (std::size_t i = 0; i < v.size(); ++i) m.at<T>(static_cast<int>(i), 0) = v[i];
    return m;
}

/// The rows of a one-column matrix (MatConstIterator divides by zero on an empty one).
template <typename T>
std::vector<T> rowsOf(const cv::Mat& m) {
    std::vector<T> v(static_cast<std::size_t>(m.rows));
    for (int i = 0; i < m.rows; ++i) v[static_cast<std::size_t>(i)] = m.at<T>(i, 0);
    return v;
}

/// OpenCV's words for a file it could not parse: a parse error carries the file and line in
/// `func` ("map.yml(45): Unexpected end of line"), other errors their condition in `err`.
std::string describe(const cv::Exception& e) {
    const auto close = e.func.find("): ");
    const auto open = e.func.rfind('(', close);
    if (e.code == cv::Error::StsParseError && close != std::string::npos &&
        open != std::string::npos)
        return "line " + e.func.substr(open + 1, close - open - 1) + ": " +
               e.func.substr(close + 3);
    return e.err.empty() ? e.msg : e.err;
}

/// Reading: every error names the file and, through `where`, the element.
struct Reader {
    std::string path;

    [[noreturn]] void fail(const std::string& where, const std::string& what) const {
        throw std::runtime_error(path + ": " + (where.empty() ? "" : where + ": ") + what);
    }
    cv::FileNode need(const cv::FileNode& parent, const char* key, const std::string& where) const {
        cv::FileNode n = parent[key];
        if (n.type() == cv::FileNode::NONE) fail(where, std::string("no '") + key + "'");
        return n;
    }
    double readFinite(const cv::FileNode& parent, const char* key, const std::string& where) const {
        const cv::FileNode n = need(parent, key, where);
        if (!n.isReal() && !n.isInt()) fail(where, std::string("'") + key + "' is not a number");
        const double v = n.real();
        if (!std::isfinite(v)) fail(where, std::string("'") + key + "' is not finite");
        return v;
    }
    int readInt(const cv::FileNode& parent, const char* key, const std::string& where) const {
        const cv::FileNode n = need(parent, key, where);
        if (!n.isInt()) fail(where, std::string("'") + key + "' is not an integer");
        return static_cast<int>(n);
    }
    /// A matrix of `type` and `cols` columns and, when rows >= 0, that many rows (or none,
    /// when `may_be_empty`).
    cv::Mat readMat(const cv::FileNode& parent, const char* key, const std::string& where, int type,
                    int cols, int rows = -1, bool may_be_empty = false) const {
        const cv::FileNode n = need(parent, key, where);
        cv::Mat m;
        if (n.isSeq() && n.size() == 0) {  // put's empty matrix
            m = cv::Mat(0, cols, type);
        } else {
            if (!n.isMap()) fail(where, std::string("'") + key + "' is not a matrix");
            n >> m;
            if (m.type() != type || m.cols != cols || m.dims != 2)
                fail(where, std::string("'") + key + "' is not a " + std::to_string(cols) +
                                "-column matrix of the expected type");
        }
        if (rows >= 0 && m.rows != rows && !(may_be_empty && m.rows == 0))
            fail(where, std::string("'") + key + "' has " + std::to_string(m.rows) + " rows for " +
                            std::to_string(rows));
        return m;
    }
    /// Every element of a floating-point matrix is finite.
    void requireFinite(const cv::Mat& m, const char* key, const std::string& where) const {
        if (!cv::checkRange(m))
            fail(where, std::string("'") + key + "' holds a value that is not finite");
    }
    Eigen::Isometry3d readPose(const cv::FileNode& parent, const char* key,
                               const std::string& where) const {
        const cv::Mat m = readMat(parent, key, where, CV_64F, 4, 3);
        requireFinite(m, key, where);
        Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) T.matrix()(r, c) = m.at<double>(r, c);
        const Eigen::Matrix3d R = T.linear();
        if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 ||
            R.determinant() < 0)
            fail(where, std::string("'") + key + "' is not a rotation and translation");
        return T;
    }
};

/// Refuses text that is not in the few line forms saveMap writes, before OpenCV 4.6's
/// FileStorage parser sees it. Two fuzzing rounds found that parser looping forever on a
/// base64 block whose 24-byte header names no type (reached through many spellings of the
/// tag), recursing without bound on nested sequences and maps however written (brackets,
/// "- - -", "a: a: a:", "------"), throwing std::length_error on an empty key, and
/// allocating whatever a matrix's rows and cols claim before reading its data; a
/// blacklist of such inputs let new spellings through, so only saveMap's forms pass:
///   %YAML:1.0 / --- (the first two lines), then, indented by spaces (at most 64):
///   "-", "[]", "KEY:", "KEY: []", "KEY: !!opencv-matrix", "data: !!binary |" followed by
///   base64 lines indented deeper, and "KEY: VALUE" with VALUE a number or a word.
void precheck(const Reader& rd, const std::string& text) {
    constexpr std::string_view kHead = "%YAML:1.0\n---\n";
    if (text.rfind("%YAML:1.0\r\n", 0) == 0)  // (it said there were no such lines)
        rd.fail("",
                "has Windows line endings (CRLF), which saveMap never writes: convert "
                "them back (dos2unix) or use the map as it was saved");
    if (text.rfind(kHead, 0) != 0)
        rd.fail("", "not a DEV-SLAM map (no '%YAML:1.0' and '---' first lines)");
    // saveMap writes this last, so that a file cut short is told as one.
    constexpr std::string_view kTail = "\nend_of_map: 1\n";
    if (text.size() < kTail.size() ||
        text.compare(text.size() - kTail.size(), kTail.size(), kTail.data(), kTail.size()) != 0)
        rd.fail("", "cut short (its last line is not 'end_of_map: 1')");
    constexpr std::size_t kMaxIndent = 64;
    const auto isWordStart = [](char c) {
        return std::isalpha(static_cast<unsigned char>(c)) || c == '_';
    };
    const auto isWord = [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
    };
    const auto isKey = [&](std::string_view k) {
        if (k.empty() || !isWordStart(k[0])) return false;
        for (const char c : k)
            if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
        return true;
    };
    // A number as OpenCV writes one ("1.", "-1.5e+00", "640"), or a word ("devslam-map", "d").
    const auto isScalar = [&](std::string_view v) {
        if (v.empty()) return false;
        if (isWordStart(v[0])) {
            for (const char c : v)
                if (!isWord(c)) return false;
            return true;
        }
        std::size_t i = 0;
        if (v[i] == '-' || v[i] == '+') ++i;
        std::size_t digits = 0;
        while (i < v.size() && std::isdigit(static_cast<unsigned char>(v[i]))) ++i, ++digits;
        if (i < v.size() && v[i] == '.') ++i;
        while (i < v.size() && std::isdigit(static_cast<unsigned char>(v[i]))) ++i, ++digits;
        if (digits == 0) return false;
        if (i < v.size() && (v[i] == 'e' || v[i] == 'E')) {
            ++i;
            if (i < v.size() && (v[i] == '-' || v[i] == '+')) ++i;
            std::size_t exp = 0;
            while (i < v.size() && std::isdigit(static_cast<unsigned char>(v[i]))) ++i, ++exp;
            if (exp == 0) return false;
        }
        return i == v.size();
    };
    const auto b64 = [](char c) -> int {
        if (c >= 'A' && c <= 'Z') return c - 'A';
        if (c >= 'a' && c <= 'z') return c - 'a' + 26;
        if (c >= '0' && c <= '9') return c - '0' + 52;
        if (c == '+') return 62;
        if (c == '/') return 63;
        return c == '=' ? 0 : -1;
    };
    // The matrix being read ("KEY: !!opencv-matrix", then rows, cols, dt, data).
    long long rows = -1, cols = -1, elem = -1;
    // The base64 block being read: its key's indentation, its header, its bytes.
    std::size_t block_indent = std::string::npos, block_line = 0;
    std::string header;
    long long block_bytes = 0;
    const auto endBlock = [&]() {
        if (block_indent == std::string::npos) return;
        const std::string where = "line " + std::to_string(block_line);
        block_indent = std::string::npos;
        // The header: the element type, as "1d" or "3f", padded with blanks.
        const std::size_t last = header.find_last_not_of(' ');
        bool typed = false, ok = header.size() == 24 && last != std::string::npos;
        for (std::size_t i = 0; ok && i <= last; ++i) {
            const char c = header[i];
            if (std::isdigit(static_cast<unsigned char>(c)))
                typed = false;
            else if (std::string_view("ucwsifdh").find(c) != std::string_view::npos)
                typed = true;
            else
                ok = false;
        }
        if (!ok || !typed) rd.fail(where, "a base64 block whose header names no type");
        if (rows < 0 || cols < 0 || elem < 0)
            rd.fail(where, "a base64 block outside a matrix with rows, cols and dt");
        if (rows * cols * elem > block_bytes - 24)
            rd.fail(where,
                    "a matrix with less data than its rows and cols say: cut short, or "
                    "not a DEV-SLAM map");
    };
    std::size_t line_no = 2;
    for (std::size_t at = kHead.size(); at < text.size();) {
        const std::size_t end = std::min(text.find('\n', at), text.size());
        const std::string_view line(text.data() + at, end - at);
        at = end + 1;
        ++line_no;
        const std::string where = "line " + std::to_string(line_no);
        const std::size_t indent = line.find_first_not_of(' ');
        if (indent == std::string_view::npos) continue;  // blank
        if (indent > kMaxIndent) rd.fail(where, "indented deeper than a DEV-SLAM map is");
        const std::string_view body = line.substr(indent);
        if (block_indent != std::string::npos && indent > block_indent) {
            std::size_t pad = 0;
            for (const char c : body) {
                if (b64(c) < 0)
                    rd.fail(where, "a base64 block holds a character that is not base64");
                pad += c == '=' ? 1 : 0;
            }
            if (body.size() % 4 != 0)
                rd.fail(where, "a base64 line whose length is no multiple of 4");
            for (std::size_t i = 0; header.size() < 24 && i + 3 < body.size(); i += 4) {
                const int v = (b64(body[i]) << 18) | (b64(body[i + 1]) << 12) |
                              (b64(body[i + 2]) << 6) | b64(body[i + 3]);
                for (const int shift : {16, 8, 0})
                    if (header.size() < 24) header += static_cast<char>((v >> shift) & 255);
            }
            block_bytes += static_cast<long long>(body.size() / 4 * 3 - pad);
            continue;
        }
        endBlock();
        if (body == "-" || body == "[]") continue;
        const std::size_t colon = body.find(':');
        if (colon == std::string_view::npos || !isKey(body.substr(0, colon)))
            rd.fail(where, "not a line a DEV-SLAM map has");
        const std::string_view key = body.substr(0, colon), rest = body.substr(colon + 1);
        if (rest.empty() || rest == " []") continue;
        if (rest[0] != ' ') rd.fail(where, "not a line a DEV-SLAM map has");
        const std::string_view value = rest.substr(1);
        if (value == "!!opencv-matrix") {
            rows = cols = elem = -1;
        } else if (value == "!!binary |" && key == "data") {
            block_indent = indent;
            block_line = line_no;
            header.clear();
            block_bytes = 0;
        } else if (!isScalar(value)) {
            rd.fail(where, "not a value a DEV-SLAM map has");
        } else if (key == "rows" || key == "cols") {
            if (value.size() > 9 || !std::isdigit(static_cast<unsigned char>(value[0])))
                rd.fail(where, "'" + std::string(key) + "' is not a count");
            (key == "rows" ? rows : cols) = std::stoll(std::string(value));
        } else if (key == "dt") {
            std::size_t i = 0;
            long long n = 0;
            while (i < value.size() && std::isdigit(static_cast<unsigned char>(value[i])) &&
                   n < 1000)
                n = n * 10 + (value[i++] - '0');
            const std::string_view type = value.substr(i);
            const std::size_t k = std::string_view("ucwsifdh").find(type);
            if (type.size() != 1 || k == std::string_view::npos)
                rd.fail(where, "'dt' is not a matrix element type");
            elem = std::max(1LL, n) * std::array<long long, 8>{1, 1, 2, 2, 4, 4, 8, 2}[k];
        }
    }
    endBlock();
}

/// A float that holds a whole number in [lo, hi].
bool wholeIn(float v, int lo, int hi) {
    return std::isfinite(v) && v == std::floor(v) && v >= static_cast<float>(lo) &&
           v <= static_cast<float>(hi);
}
}  // namespace

void saveMap(const std::string& path, const Map& map, const OrbExtractor::Options& orb,
             const core::CameraIntrinsics& camera) {
    cv::FileStorage fs(".yml",
                       cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::BASE64);
    fs << "format" << kFormat << "version" << kVersion;
    fs << "orb_scale_factor" << orb.scale_factor << "orb_n_levels" << orb.n_levels;
    fs << "camera"
       << "{"
       << "fx" << camera.fx << "fy" << camera.fy << "cx" << camera.cx << "cy" << camera.cy
       << "width" << camera.width << "height" << camera.height;
    put(fs, "dist", cv::Mat(1, 5, CV_64F, const_cast<double*>(camera.dist.data())));
    fs << "}";
    fs << "keyframes"
       << "[";
    for (const auto& [id, kf] : map.keyframes()) {
        const FrameFeatures& f = kf.features;
        const int n = static_cast<int>(f.size());
        fs << "{";
        fs << "id" << asInt(id, "keyframe id");
        fs << "frame_index" << asInt(static_cast<std::int64_t>(kf.frame_index), "frame index");
        fs << "timestamp" << kf.timestamp;
        cv::Mat T(3, 4, CV_64F);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) T.at<double>(r, c) = kf.T_wc.matrix()(r, c);
        fs << "T_wc" << T;
        cv::Mat kp(n, kKeypointCols, CV_32F), pc(n, 3, CV_64F), col(n, 3, CV_8U);
        for (int i = 0; i < n; ++i) {
            const auto& k = f.keypoints[static_cast<std::size_t>(i)];
            const float row[kKeypointCols] = {k.pt.x,
                                              k.pt.y,
                                              k.size,
                                              k.angle,
                                              k.response,
                                              static_cast<float>(k.octave),
                                              static_cast<float>(k.class_id)};
            std::copy(row, row + kKeypointCols, kp.ptr<float>(i));
            for (int c = 0; c < 3; ++c) {
                pc.at<double>(i, c) = f.points_c[static_cast<std::size_t>(i)][c];
                col.at<unsigned char>(i, c) = f.colors[static_cast<std::size_t>(i)][c];
            }
        }
        cv::Mat image_pt(static_cast<int>(f.image_pt.size()), 2, CV_32F);
        for (int i = 0; i < image_pt.rows; ++i) {
            image_pt.at<float>(i, 0) = f.image_pt[static_cast<std::size_t>(i)].x;
            image_pt.at<float>(i, 1) = f.image_pt[static_cast<std::size_t>(i)].y;
        }
        put(fs, "keypoints", kp);
        put(fs, "descriptors", f.descriptors);
        put(fs, "depth", column(f.depth, CV_32F));
        put(fs, "points_c", pc);
        put(fs, "colors", col);
        put(fs, "image_pt", image_pt);
        put(fs, "weight", column(f.weight, CV_32F));
        fs << "gate_exponent" << f.gate_exponent;
        fs << "n_masked" << f.n_masked << "masked_fraction" << f.masked_fraction;
        fs << "}";
    }
    fs << "]";
    // The landmarks column by column, in id order.
    std::vector<LandmarkId> ids;
    ids.reserve(map.landmarks().size());
    for (const auto& [id, lm] : map.landmarks()) ids.push_back(id);
    std::sort(ids.begin(), ids.end());
    const int n = static_cast<int>(ids.size());
    cv::Mat p_w(n, 3, CV_64F), desc(n, 32, CV_8U), color(n, 3, CV_8U);
    std::vector<int> lid, ref_kf, created_kf, n_visible, n_found, n_obs, obs;
    for (int i = 0; i < n; ++i) {
        const Landmark& lm = *map.landmark(ids[static_cast<std::size_t>(i)]);
        for (int c = 0; c < 3; ++c) {
            p_w.at<double>(i, c) = lm.p_w[c];
            color.at<unsigned char>(i, c) = lm.color[c];
        }
        lm.descriptor.reshape(1, 1).copyTo(desc.row(i));
        lid.push_back(asInt(lm.id, "landmark id"));
        // A landmark's creator may have been culled since: -1, as for none.
        ref_kf.push_back(lm.ref_kf == kNoId ? -1 : asInt(lm.ref_kf, "keyframe id"));
        created_kf.push_back(lm.created_kf == kNoId ? -1 : asInt(lm.created_kf, "keyframe id"));
        n_visible.push_back(lm.n_visible);
        n_found.push_back(lm.n_found);
        n_obs.push_back(static_cast<int>(lm.observations.size()));
        for (const auto& [k, kp] : lm.observations) {
            obs.push_back(asInt(k, "keyframe id"));
            obs.push_back(kp);
        }
    }
    fs << "landmarks"
       << "{";
    fs << "count" << n;
    put(fs, "id", column(lid, CV_32S));
    put(fs, "p_w", p_w);
    put(fs, "descriptors", desc);
    put(fs, "colors", color);
    put(fs, "ref_kf", column(ref_kf, CV_32S));
    put(fs, "created_kf", column(created_kf, CV_32S));
    put(fs, "n_visible", column(n_visible, CV_32S));
    put(fs, "n_found", column(n_found, CV_32S));
    put(fs, "n_observations", column(n_obs, CV_32S));
    put(fs, "observations", column(obs, CV_32S).reshape(1, static_cast<int>(obs.size() / 2)));
    fs << "}";
    // Last, so that a file cut short (which YAML may still parse) is told as one.
    fs << "end_of_map" << 1;
    core::writeFileWhole(path, fs.releaseAndGetString());
}

MapFile loadMap(const std::string& path) {
    const Reader rd{path};
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        rd.fail("", std::filesystem::exists(path, ec) ? "not a file" : "no such file");
    // Read here and given to OpenCV as text, not as a path: it would take a name ending in
    // ".gz" for a gzip file (1 MB of it took 2.4 GB to unpack) and cut a name at a '?'
    // (reading another file).
    // (OpenCV's parser takes some 5-12 times a file's size in memory; a 90-keyframe map of a
    // 750-frame render is 18 MB.)
    constexpr std::uintmax_t kMaxBytes = std::uintmax_t{512} << 20;
    const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
    if (ec) rd.fail("", "cannot be read (" + ec.message() + ")");
    if (bytes > kMaxBytes)
        rd.fail("", std::to_string(bytes) + " bytes: larger than the 512 MiB a map is read up to");
    std::string text;
    {
        std::ifstream in(path, std::ios::binary);
        text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        if (!in && !in.eof()) rd.fail("", "cannot be read");
    }
    precheck(rd, text);
    cv::FileStorage fs;
    try {
        if (!fs.open(text, cv::FileStorage::READ | cv::FileStorage::MEMORY))
            rd.fail("", "cannot be read");
    } catch (const cv::Exception& e) {
        // A file cut short or not YAML/JSON/XML: OpenCV's parser names the line.
        rd.fail("", "not a DEV-SLAM map, or cut short (OpenCV: " + describe(e) + ")");
    } catch (const std::exception& e) {  // std::bad_alloc, std::length_error in the parser
        rd.fail("", std::string("not a DEV-SLAM map, or too large to read (") + e.what() + ")");
    }
    try {
        const cv::FileNode root = fs.root();
        if (!root.isMap() || !root["format"].isString() ||
            static_cast<std::string>(root["format"]) != kFormat)
            rd.fail("", std::string("not a DEV-SLAM map (no 'format: ") + kFormat + "')");
        const int version = rd.readInt(root, "version", "");
        if (version != kVersion)
            rd.fail("", "format version " + std::to_string(version) + ", this build reads " +
                            std::to_string(kVersion));
        MapFile out;
        out.orb_scale_factor = rd.readFinite(root, "orb_scale_factor", "");
        out.orb_n_levels = rd.readInt(root, "orb_n_levels", "");
        if (out.orb_scale_factor <= 1 || out.orb_n_levels < 1 || out.orb_n_levels > 32)
            rd.fail("", "orb_scale_factor must be > 1 and orb_n_levels in [1, 32]");
        {
            const std::string cw = "camera";
            const cv::FileNode cn = rd.need(root, "camera", "");
            if (!cn.isMap()) rd.fail(cw, "not a map of fields");
            core::CameraIntrinsics& K = out.camera;
            K.fx = rd.readFinite(cn, "fx", cw);
            K.fy = rd.readFinite(cn, "fy", cw);
            K.cx = rd.readFinite(cn, "cx", cw);
            K.cy = rd.readFinite(cn, "cy", cw);
            K.width = rd.readInt(cn, "width", cw);
            K.height = rd.readInt(cn, "height", cw);
            const cv::Mat d = rd.readMat(cn, "dist", cw, CV_64F, 5, 1);
            rd.requireFinite(d, "dist", cw);
            for (int i = 0; i < 5; ++i) K.dist[static_cast<std::size_t>(i)] = d.at<double>(0, i);
            if (K.fx <= 0 || K.fy <= 0 || K.width <= 0 || K.height <= 0)
                rd.fail(cw, "fx, fy, width and height must be positive");
        }

        // Keyframes, renumbered in the saved order.
        const cv::FileNode kfs = rd.need(root, "keyframes", "");
        if (!kfs.isSeq()) rd.fail("", "'keyframes' is not a list");
        std::map<int, KeyframeId> kf_new;  // saved id -> id in the loaded map
        int k_index = 0;
        for (const cv::FileNode& kn : kfs) {
            const std::string where = "keyframe " + std::to_string(k_index++);
            if (!kn.isMap()) rd.fail(where, "not a map of fields");
            Keyframe kf;
            const int saved_id = rd.readInt(kn, "id", where);
            const int frame_index = rd.readInt(kn, "frame_index", where);
            if (frame_index < 0) rd.fail(where, "negative frame_index");
            kf.frame_index = static_cast<std::size_t>(frame_index);
            kf.timestamp = rd.readFinite(kn, "timestamp", where);
            kf.T_wc = rd.readPose(kn, "T_wc", where);
            const cv::Mat kp = rd.readMat(kn, "keypoints", where, CV_32F, kKeypointCols);
            const int n = kp.rows;
            FrameFeatures& f = kf.features;
            for (int i = 0; i < n; ++i) {
                const float* r = kp.ptr<float>(i);
                if (!std::isfinite(r[0]) || !std::isfinite(r[1]) || !std::isfinite(r[2]) ||
                    r[2] < 0 || !std::isfinite(r[3]) || !std::isfinite(r[4]) ||
                    !wholeIn(r[5], 0, out.orb_n_levels - 1) || !wholeIn(r[6], -1000000, 1000000))
                    rd.fail(where, "keypoint " + std::to_string(i) +
                                       ": a value that is not finite, a negative size, or an "
                                       "octave outside the pyramid");
                f.keypoints.emplace_back(r[0], r[1], r[2], r[3], r[4], static_cast<int>(r[5]),
                                         static_cast<int>(r[6]));
            }
            f.descriptors = rd.readMat(kn, "descriptors", where, CV_8U, 32, n);
            const cv::Mat depth = rd.readMat(kn, "depth", where, CV_32F, 1, n);
            rd.requireFinite(depth, "depth", where);
            f.depth = rowsOf<float>(depth);
            const cv::Mat pc = rd.readMat(kn, "points_c", where, CV_64F, 3, n);
            rd.requireFinite(pc, "points_c", where);
            const cv::Mat col = rd.readMat(kn, "colors", where, CV_8U, 3, n);
            for (int i = 0; i < n; ++i) {
                f.points_c.emplace_back(pc.at<double>(i, 0), pc.at<double>(i, 1),
                                        pc.at<double>(i, 2));
                f.colors.emplace_back(col.at<unsigned char>(i, 0), col.at<unsigned char>(i, 1),
                                      col.at<unsigned char>(i, 2));
            }
            const cv::Mat ip = rd.readMat(kn, "image_pt", where, CV_32F, 2, n, true);
            rd.requireFinite(ip, "image_pt", where);
            for (int i = 0; i < ip.rows; ++i)
                f.image_pt.emplace_back(ip.at<float>(i, 0), ip.at<float>(i, 1));
            const cv::Mat w = rd.readMat(kn, "weight", where, CV_32F, 1, n, true);
            rd.requireFinite(w, "weight", where);
            f.weight = rowsOf<float>(w);
            f.gate_exponent = rd.readFinite(kn, "gate_exponent", where);
            f.n_masked = rd.readInt(kn, "n_masked", where);
            f.masked_fraction = rd.readFinite(kn, "masked_fraction", where);
            if (kf_new.count(saved_id)) rd.fail(where, "id " + std::to_string(saved_id) + " twice");
            kf_new[saved_id] = out.map.addKeyframe(std::move(kf));
        }

        // Landmarks.
        const cv::FileNode ln = rd.need(root, "landmarks", "");
        if (!ln.isMap()) rd.fail("", "'landmarks' is not a map of fields");
        const std::string lw = "landmarks";
        const int n = rd.readInt(ln, "count", lw);
        if (n < 0) rd.fail(lw, "negative count");
        const cv::Mat p_w = rd.readMat(ln, "p_w", lw, CV_64F, 3, n);
        const cv::Mat desc = rd.readMat(ln, "descriptors", lw, CV_8U, 32, n);
        const cv::Mat color = rd.readMat(ln, "colors", lw, CV_8U, 3, n);
        const cv::Mat ids = rd.readMat(ln, "id", lw, CV_32S, 1, n);
        const cv::Mat ref_kf = rd.readMat(ln, "ref_kf", lw, CV_32S, 1, n);
        const cv::Mat created_kf = rd.readMat(ln, "created_kf", lw, CV_32S, 1, n);
        const cv::Mat n_visible = rd.readMat(ln, "n_visible", lw, CV_32S, 1, n);
        const cv::Mat n_found = rd.readMat(ln, "n_found", lw, CV_32S, 1, n);
        const cv::Mat n_obs = rd.readMat(ln, "n_observations", lw, CV_32S, 1, n);
        const cv::Mat obs = rd.readMat(ln, "observations", lw, CV_32S, 2);
        std::set<std::pair<KeyframeId, int>> seen;
        int o = 0;
        const auto kfOf = [&](int saved, const std::string& where) -> KeyframeId {
            const auto it = kf_new.find(saved);
            if (it == kf_new.end())
                rd.fail(where, "keyframe id " + std::to_string(saved) + " is not in the map");
            return it->second;
        };
        for (int i = 0; i < n; ++i) {
            const std::string where =
                "landmark " + std::to_string(i) + " (id " + std::to_string(ids.at<int>(i, 0)) + ")";
            const Eigen::Vector3d p(p_w.at<double>(i, 0), p_w.at<double>(i, 1),
                                    p_w.at<double>(i, 2));
            if (!p.allFinite()) rd.fail(where, "a position that is not finite");
            const int k_obs = n_obs.at<int>(i, 0);
            if (k_obs < 1) rd.fail(where, "no observation");
            if (k_obs > obs.rows - o) rd.fail(where, "'observations' ends before its observations");
            LandmarkId lm = kNoId;
            for (int j = 0; j < k_obs; ++j, ++o) {
                const int saved_kf = obs.at<int>(o, 0), kp = obs.at<int>(o, 1);
                const KeyframeId k = kfOf(saved_kf, where);
                if (kp < 0 || kp >= static_cast<int>(out.map.keyframe(k).features.size()))
                    rd.fail(where, "keyframe id " + std::to_string(saved_kf) + " has no keypoint " +
                                       std::to_string(kp));
                if (!seen.emplace(k, kp).second)
                    rd.fail(where, "keypoint " + std::to_string(kp) + " of keyframe id " +
                                       std::to_string(saved_kf) + " observes two landmarks");
                if (lm == kNoId) {
                    const cv::Vec3b c(color.at<unsigned char>(i, 0), color.at<unsigned char>(i, 1),
                                      color.at<unsigned char>(i, 2));
                    lm = out.map.addLandmark(p, desc.row(i), c, k, kp);
                } else {
                    out.map.addObservation(lm, k, kp);
                }
            }
            Landmark& l = *out.map.landmark(lm);
            // The anchor must be in the map; the creator may have been culled before saving.
            l.ref_kf = kfOf(ref_kf.at<int>(i, 0), where);
            const auto created = kf_new.find(created_kf.at<int>(i, 0));
            l.created_kf = created == kf_new.end() ? kNoId : created->second;
            l.n_visible = n_visible.at<int>(i, 0);
            l.n_found = n_found.at<int>(i, 0);
        }
        if (o != obs.rows)
            rd.fail(lw, "'observations' has " + std::to_string(obs.rows - o) +
                            " rows past the last landmark's");
        return out;
    } catch (const cv::Exception& e) {
        rd.fail("", "not a DEV-SLAM map, or cut short (OpenCV: " + describe(e) + ")");
    } catch (const std::bad_alloc& e) {
        rd.fail("", std::string("too large to read (") + e.what() + ")");
    } catch (const std::length_error& e) {
        rd.fail("", std::string("not a DEV-SLAM map (") + e.what() + ")");
    }
}

void checkOrbMatches(const MapFile& m, const std::string& path, const OrbExtractor::Options& orb) {
    if (std::abs(m.orb_scale_factor - orb.scale_factor) > 1e-9 || m.orb_n_levels != orb.n_levels)
        throw std::invalid_argument(
            path + ": the map's keypoints come from an ORB pyramid of scale_factor " +
            std::to_string(m.orb_scale_factor) + ", n_levels " + std::to_string(m.orb_n_levels) +
            "; this run's [orb] has " + std::to_string(orb.scale_factor) + ", " +
            std::to_string(orb.n_levels) + " (localize with the INI the map was made with)");
}

void checkCameraMatches(const MapFile& m, const std::string& path,
                        const core::CameraIntrinsics& camera) {
    const core::CameraIntrinsics& a = m.camera;
    // What differs beyond its tolerance, in full (the summaries below round to 0.1 px and
    // may read the same); nothing: the same camera.
    std::string differs;
    const auto check = [&](const std::string& name, double x, double y, double tol) {
        if (std::abs(x - y) <= tol) return;
        char b[128];
        std::snprintf(b, sizeof b, "%s%s %.10g in the map, %.10g in the input",
                      differs.empty() ? "" : "; ", name.c_str(), x, y);
        differs += b;
    };
    check("width", a.width, camera.width, 0);
    check("height", a.height, camera.height, 0);
    check("fx", a.fx, camera.fx, 1e-6);
    check("fy", a.fy, camera.fy, 1e-6);
    check("cx", a.cx, camera.cx, 1e-6);
    check("cy", a.cy, camera.cy, 1e-6);
    for (std::size_t i = 0; i < a.dist.size(); ++i)
        check("dist[" + std::to_string(i) + "]", a.dist[i], camera.dist[i], 1e-9);
    if (differs.empty()) return;
    const auto text = [](const core::CameraIntrinsics& k) {
        char b[160];
        std::snprintf(b, sizeof b, "fx=%.1f fy=%.1f cx=%.1f cy=%.1f %dx%d dist=[%g %g %g %g %g]",
                      k.fx, k.fy, k.cx, k.cy, k.width, k.height, k.dist[0], k.dist[1], k.dist[2],
                      k.dist[3], k.dist[4]);
        return std::string(b);
    };
    throw std::invalid_argument(path + ": the map was made with the camera " + text(a) +
                                ", the input's is " + text(camera) + " (" + differs +
                                "): its keyframes cannot be adjusted with another camera's "
                                "pixels (localize without --extend-map)");
}

}  // namespace devslam::slam
