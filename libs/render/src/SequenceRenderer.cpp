#include <devslam/render/PersonTexture.h>
#include <devslam/render/SequenceRenderer.h>

#include <devslam/core/Picture.h>

#include <mrpt/img/CImage.h>
#include <mrpt/img/TCamera.h>
#include <mrpt/math/CMatrixDynamic.h>
#include <mrpt/opengl/CFBORender.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CSetOfTexturedTriangles.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <map>
#include <random>
#include <stdexcept>

namespace devslam::render {
namespace {

using mrpt::opengl::CSetOfTexturedTriangles;

/// splitmix64: decorrelates (seed, frame, stream) into one 64-bit seed.
std::uint64_t mixSeed(std::uint64_t a, std::uint64_t b, std::uint64_t c) {
    std::uint64_t x = a * 0x9E3779B97F4A7C15ull ^
                      (b + 0x632BE59BD9B4E019ull) * 0xBF58476D1CE4E5B9ull ^
                      (c + 1) * 0x94D049BB133111EBull;
    x ^= x >> 30;
    x *= 0xBF58476D1CE4E5B9ull;
    x ^= x >> 27;
    x *= 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

mrpt::math::TPoint3Df toF(const Eigen::Vector3d& p) {
    return {float(p.x()), float(p.y()), float(p.z())};
}

/// Two triangles p0-p1-p2, p0-p2-p3 with texture corners (u0,v0) at p0 ... (uv in [0,1],
/// v = 0 at the first image row).
void addQuad(CSetOfTexturedTriangles& obj, const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
             const Eigen::Vector3d& p2, const Eigen::Vector3d& p3, float u0, float v0, float u1,
             float v1) {
    mrpt::opengl::TTriangle a, b;
    const auto set = [](mrpt::opengl::TTriangle& t, int k, const Eigen::Vector3d& p, float u,
                        float v) {
        t.vertices[k].xyzrgba.pt = toF(p);
        t.vertices[k].xyzrgba.r = t.vertices[k].xyzrgba.g = t.vertices[k].xyzrgba.b =
            t.vertices[k].xyzrgba.a = 255;
        t.vertices[k].uv = {u, v};
    };
    set(a, 0, p0, u0, v0);
    set(a, 1, p1, u1, v0);
    set(a, 2, p2, u1, v1);
    set(b, 0, p0, u0, v0);
    set(b, 1, p2, u1, v1);
    set(b, 2, p3, u0, v1);
    a.computeNormals();
    b.computeNormals();
    obj.insertTriangle(a);
    obj.insertTriangle(b);
}

mrpt::img::CImage toCImage(const cv::Mat& bgr) {
    return mrpt::img::CImage(bgr, mrpt::img::DEEP_COPY);
}

/// A random crop (50-90% of each side) of a photo, flipped at random: every panel of the
/// room looks different, so the ORB matcher does not see the same texture twice.
cv::Mat panelCrop(const cv::Mat& img, std::mt19937_64& rng, double aspect) {
    std::uniform_real_distribution<double> frac(0.5, 0.9), pos(0.0, 1.0);
    int w = int(img.cols * frac(rng));
    int h = int(w / aspect);
    if (h > img.rows) {
        h = img.rows;
        w = int(h * aspect);
    }
    w = std::max(8, std::min(w, img.cols));
    h = std::max(8, std::min(h, img.rows));
    const int x = int((img.cols - w) * pos(rng)), y = int((img.rows - h) * pos(rng));
    cv::Mat crop = img(cv::Rect(x, y, w, h)).clone();
    if (pos(rng) < 0.5) cv::flip(crop, crop, 1);
    return crop;
}

/// Adds Gaussian noise of `sigma` grey levels to each channel (saturating), seeded.
void addRgbNoise(cv::Mat& bgr, double sigma, std::uint64_t seed) {
    cv::Mat noise(bgr.size(), CV_32FC3);
    std::mt19937_64 rng(seed);
    std::normal_distribution<float> g(0.f, float(sigma));
    for (auto it = noise.begin<cv::Vec3f>(); it != noise.end<cv::Vec3f>(); ++it) {
        // Drawn in a stated order (a call's arguments have none, and another compiler gave
        // other renders): last channel first, as GCC evaluated Vec3f(g(rng), g(rng), g(rng))
        // for every render so far.
        const float c2 = g(rng);
        const float c1 = g(rng);
        const float c0 = g(rng);
        *it = cv::Vec3f(c0, c1, c2);
    }
    cv::Mat f;
    bgr.convertTo(f, CV_32FC3);
    f += noise;
    f.convertTo(bgr, CV_8UC3);  // saturating
}

/// One planar part of a person (the body, or the hand in front of it when it gestures).
struct PersonPart {
    mrpt::poses::CPose3D P;
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // columns: local x, y (normal), z
    Eigen::Vector3d p0 = Eigen::Vector3d::Zero();
    bool hand = false;
};

PersonPart personPart(const mrpt::poses::CPose3D& P, bool hand) {
    PersonPart part;
    part.P = P;
    const auto Rp = P.getRotationMatrix();
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) part.R(r, c) = Rp(r, c);
    part.p0 = {P.x(), P.y(), P.z()};
    part.hand = hand;
    return part;
}

/// The image rectangle that holds the projection of the parts' corners (a width x height
/// photo each), one pixel wider all round; the whole image when a corner is behind the camera.
cv::Rect projectedBox(const std::vector<PersonPart>& parts, double width, double height,
                      const mrpt::poses::CPose3D& T_wc, const core::CameraIntrinsics& K) {
    cv::Rect roi(0, 0, K.width, K.height);
    double u0 = 1e9, v0 = 1e9, u1 = -1e9, v1 = -1e9;
    for (const auto& part : parts) {
        for (double lx : {-width / 2, width / 2})
            for (double lz : {0.0, height}) {
                mrpt::math::TPoint3D w;
                part.P.composePoint(lx, 0, lz, w.x, w.y, w.z);
                mrpt::math::TPoint3D c;
                T_wc.inverseComposePoint(w, c);
                if (c.z < 1e-3) return roi;
                const double u = K.fx * c.x / c.z + K.cx, v = K.fy * c.y / c.z + K.cy;
                u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, v),
                v1 = std::max(v1, v);
            }
    }
    return roi & cv::Rect(int(std::floor(u0)) - 1, int(std::floor(v0)) - 1,
                          int(std::ceil(u1 - u0)) + 3, int(std::ceil(v1 - v0)) + 3);
}

}  // namespace

struct SequenceRenderer::Impl {
    mrpt::opengl::COpenGLScene::Ptr scene;
    std::unique_ptr<mrpt::opengl::CFBORender> fbo;
    std::map<std::pair<std::string, double>, cv::Mat> photos;  // (path, blur) -> BGR
    bool texture_linear = true;  // Scenario::texture_linear, for every textured object
    /// The camera's position in the first frame: seated and standing people face it.
    Eigen::Vector3d first_eye{0, 0, 0};
    struct Person {
        PersonTexture tex;
        double width = 0, height = 0;  // [m]
        CSetOfTexturedTriangles::Ptr mesh;
        CSetOfTexturedTriangles::Ptr hand;  // the gesture_region's cells (null: no gesture)
        cv::Mat hand_cell;                  // CV_8UC1 like tex.cell_mask: 255 = a hand cell
    };
    std::vector<Person> people;

    /// The photo at `path`, blurred with a Gaussian of sigma `blur` px (0 = as read).
    const cv::Mat& photo(const std::string& path, double blur = 0.0) {
        const auto key = std::make_pair(path, blur);
        auto it = photos.find(key);
        if (it != photos.end()) return it->second;
        std::string why;
        cv::Mat img = core::readImage(path, cv::IMREAD_COLOR, why);
        if (img.empty())
            throw std::runtime_error("render: cannot read texture '" + path + "'" + why);
        // (panelCrop cuts at least 8 x 8 px: a smaller photo failed in an OpenCV assertion)
        if (img.cols < 8 || img.rows < 8)
            throw std::runtime_error("render: texture '" + path + "' is " +
                                     std::to_string(img.cols) + "x" + std::to_string(img.rows) +
                                     " px; at least 8x8 needed");
        if (const auto big = textureTooLarge(img, path); !big.empty())
            throw std::runtime_error("render: " + big);
        if (blur > 0) cv::GaussianBlur(img, img, cv::Size(), blur);
        return photos.emplace(key, img).first->second;
    }

    /// A rectangle given by an origin corner and two edge vectors, covered by panels of at
    /// most pw x ph metres, each with its own photo crop.
    void addPanelled(const Eigen::Vector3d& origin, const Eigen::Vector3d& right,
                     const Eigen::Vector3d& down, double pw, double ph,
                     const std::vector<std::string>& files, std::size_t& counter,
                     std::mt19937_64& rng, double blur = 0.0) {
        const double W = right.norm(), H = down.norm();
        const Eigen::Vector3d ex = right / W, ey = down / H;
        const int nx = std::max(1, int(std::ceil(W / pw - 1e-9)));
        const int ny = std::max(1, int(std::ceil(H / ph - 1e-9)));
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                const double x0 = i * W / nx, x1 = (i + 1) * W / nx;
                const double y0 = j * H / ny, y1 = (j + 1) * H / ny;
                const cv::Mat crop = panelCrop(photo(files[counter++ % files.size()], blur), rng,
                                               (x1 - x0) / (y1 - y0));
                auto obj = CSetOfTexturedTriangles::Create();
                addQuad(*obj, origin + ex * x0 + ey * y0, origin + ex * x1 + ey * y0,
                        origin + ex * x1 + ey * y1, origin + ex * x0 + ey * y1, 0.f, 0.f, 1.f, 1.f);
                obj->assignImage(toCImage(crop));
                obj->enableTextureLinearInterpolation(texture_linear);
                obj->enableLight(false);
                scene->insert(obj);
            }
    }

    void buildRoom(const Scenario& sc) {
        std::mt19937_64 rng(mixSeed(sc.seed, 0xA11, 7));
        const auto& r = sc.room;
        const double X = r.size.x(), Y = r.size.y(), Z = r.size.z();
        std::size_t k = 0;
        const double pw = r.panel_width, ph = r.panel_height;
        const auto wall = [&](const Eigen::Vector3d& o, const Eigen::Vector3d& right,
                              const Eigen::Vector3d& down) {
            addPanelled(o, right, down, pw, ph, r.wall_textures, k, rng, r.wall_blur);
        };
        // Walls: origin = the top corner on the right as seen from inside the room, so each
        // photo runs right to left, mirrored (panelCrop mirrors half the crops anyway).
        wall({X, 0, Z}, {0, Y, 0}, {0, 0, -Z});   // x = X
        wall({0, Y, Z}, {0, -Y, 0}, {0, 0, -Z});  // x = 0
        wall({X, Y, Z}, {-X, 0, 0}, {0, 0, -Z});  // y = Y
        wall({0, 0, Z}, {X, 0, 0}, {0, 0, -Z});   // y = 0
        std::size_t kf = 0;
        addPanelled({0, Y, 0}, {X, 0, 0}, {0, -Y, 0}, pw, ph, r.floor_textures, kf, rng,
                    r.floor_blur);              // floor
        wall({0, 0, Z}, {X, 0, 0}, {0, Y, 0});  // ceiling
        for (const auto& b : r.boxes) {
            const double c = std::cos(b.yaw), s = std::sin(b.yaw);
            const auto P = [&](double lx, double ly, double lz) {
                return Eigen::Vector3d(b.base.x() + c * lx - s * ly, b.base.y() + s * lx + c * ly,
                                       b.base.z() + lz);
            };
            const double hx = b.size.x() / 2, hy = b.size.y() / 2, hz = b.size.z();
            std::size_t kb = 0;
            const auto face = [&](const Eigen::Vector3d& o, const Eigen::Vector3d& a,
                                  const Eigen::Vector3d& d) {
                addPanelled(o, a - o, d - o, 1e9, 1e9, b.textures, kb, rng, b.blur);
            };
            face(P(hx, -hy, hz), P(hx, hy, hz), P(hx, -hy, 0));     // +x
            face(P(-hx, hy, hz), P(-hx, -hy, hz), P(-hx, hy, 0));   // -x
            face(P(hx, hy, hz), P(-hx, hy, hz), P(hx, hy, 0));      // +y
            face(P(-hx, -hy, hz), P(hx, -hy, hz), P(-hx, -hy, 0));  // -y
            face(P(-hx, hy, hz), P(hx, hy, hz), P(-hx, -hy, hz));   // top
        }
    }

    /// Person k's truth in one frame: the pixels whose ray, at the rendered depth, meets the
    /// person's solid cells, written as k + 1 into `labels`, and their box.
    PersonTruth labelPerson(std::size_t k, const std::vector<PersonPart>& parts,
                            const mrpt::poses::CPose3D& T_wc, const core::CameraIntrinsics& K,
                            const cv::Mat& clean_depth, cv::Mat& labels) const {
        const auto& person = people[k];
        PersonTruth pt;
        pt.id = int(k + 1);
        const Eigen::Vector3d eye(T_wc.x(), T_wc.y(), T_wc.z());
        const auto Rwc = T_wc.getRotationMatrix();
        const cv::Rect roi = projectedBox(parts, person.width, person.height, T_wc, K);
        const auto& m = person.tex.cell_mask;
        const double tw = person.tex.bgr.cols, th = person.tex.bgr.rows, cp = person.tex.cell_px;
        // Pixel (u, v) at rendered depth zr along world ray dw lies on the part's solid cells.
        const auto onPart = [&](const PersonPart& part, const Eigen::Vector3d& dw, float zr) {
            const Eigen::Vector3d n = part.R.col(1);
            const double den = n.dot(dw);
            if (std::abs(den) < 1e-9) return false;
            const double s = n.dot(part.p0 - eye) / den;  // = depth along the optical axis
            if (s <= 0 || std::abs(zr - s) > std::max(0.01, 0.005 * s)) return false;
            const Eigen::Vector3d q = eye + s * dw - part.p0;
            const double lx = part.R.col(0).dot(q), lz = part.R.col(2).dot(q);
            const double col = (person.width / 2 - lx) / person.width * tw;
            const double row = (person.height - lz) / person.height * th;
            if (col < 0 || row < 0 || col >= tw || row >= th) return false;
            const int r = int(row / cp), c = int(col / cp);
            return m.at<uchar>(r, c) && (person.hand_cell.at<uchar>(r, c) != 0) == part.hand;
        };
        int umin = K.width, vmin = K.height, umax = -1, vmax = -1;
        for (int v = roi.y; v < roi.y + roi.height; ++v)
            for (int u = roi.x; u < roi.x + roi.width; ++u) {
                const float zr = clean_depth.at<float>(v, u);
                if (zr <= 0) continue;
                const Eigen::Vector3d dc((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
                Eigen::Vector3d dw;
                for (int r = 0; r < 3; ++r)
                    dw[r] = Rwc(r, 0) * dc[0] + Rwc(r, 1) * dc[1] + Rwc(r, 2) * dc[2];
                bool hit = false;
                for (const auto& part : parts) hit = hit || onPart(part, dw, zr);
                if (!hit) continue;
                labels.at<uchar>(v, u) = uchar(pt.id);
                ++pt.visible_pixels;
                umin = std::min(umin, u), umax = std::max(umax, u);
                vmin = std::min(vmin, v), vmax = std::max(vmax, v);
            }
        if (pt.visible_pixels > 0) pt.box = cv::Rect(umin, vmin, umax - umin + 1, vmax - vmin + 1);
        return pt;
    }

    void buildPeople(const Scenario& sc) {
        for (const auto& spec : sc.people) {
            Person p;
            p.tex = loadPersonTexture(spec.texture);
            p.height = spec.height;
            p.width = spec.height * p.tex.aspect();
            p.mesh = CSetOfTexturedTriangles::Create();
            const auto& m = p.tex.cell_mask;
            const double tw = p.tex.bgr.cols, th = p.tex.bgr.rows, cp = p.tex.cell_px;
            // A cell belongs to the hand when its centre lies in the gesture region.
            p.hand_cell = cv::Mat(m.size(), CV_8UC1, cv::Scalar(0));
            if (spec.gestures()) {
                p.hand = CSetOfTexturedTriangles::Create();
                const auto& g = spec.gesture_region;
                for (int r = 0; r < m.rows; ++r)
                    for (int c = 0; c < m.cols; ++c) {
                        const double fc = std::min(tw, (c + 0.5) * cp) / tw;
                        const double fr = std::min(th, (r + 0.5) * cp) / th;
                        if (fc >= g[0] && fc <= g[2] && fr >= g[1] && fr <= g[3])
                            p.hand_cell.at<uchar>(r, c) = 255;
                    }
            }
            // Local frame: x lateral, y towards the viewer, z up; texture column 0 at +x so
            // that the photo reads the right way round for a viewer on the +y side.
            for (int r = 0; r < m.rows; ++r)
                for (int c = 0; c < m.cols; ++c) {
                    if (!m.at<uchar>(r, c)) continue;
                    const double c0 = c * cp, c1 = std::min(tw, (c + 1) * cp);
                    const double r0 = r * cp, r1 = std::min(th, (r + 1) * cp);
                    const auto X = [&](double col) { return p.width / 2 - col / tw * p.width; };
                    const auto Z = [&](double row) { return p.height - row / th * p.height; };
                    addQuad(p.hand_cell.at<uchar>(r, c) ? *p.hand : *p.mesh, {X(c0), 0, Z(r0)},
                            {X(c1), 0, Z(r0)}, {X(c1), 0, Z(r1)}, {X(c0), 0, Z(r1)}, float(c0 / tw),
                            float(r0 / th), float(c1 / tw), float(r1 / th));
                }
            for (const auto& mesh : {p.mesh, p.hand}) {
                if (!mesh) continue;
                mesh->assignImage(toCImage(p.tex.bgr));
                mesh->enableTextureLinearInterpolation(texture_linear);
                mesh->enableLight(false);
                scene->insert(mesh);
            }
            people.push_back(std::move(p));
        }
    }
};

SequenceRenderer::SequenceRenderer(Scenario sc)
    : sc_(std::move(sc)), impl_(std::make_unique<Impl>()) {
    if (sc_.K.width < 8 || sc_.K.height < 8)
        throw std::invalid_argument("render: image size must be at least 8x8");
    const auto T0 = cameraPoseAt(sc_.trajectory, 0.0);
    impl_->first_eye = {T0.x(), T0.y(), T0.z()};
    impl_->scene = mrpt::opengl::COpenGLScene::Create();
    auto vp = impl_->scene->getViewport();
    vp->setViewportClipDistances(sc_.near_clip, sc_.far_clip);
    vp->setCustomBackgroundColor({0.f, 0.f, 0.f});
    impl_->texture_linear = sc_.texture_linear;
    impl_->buildRoom(sc_);
    impl_->buildPeople(sc_);
    try {
        impl_->fbo = std::make_unique<mrpt::opengl::CFBORender>(unsigned(sc_.K.width),
                                                                unsigned(sc_.K.height));
    } catch (const std::exception& e) {
        throw std::runtime_error(std::string("render: cannot create the headless EGL context: ") +
                                 e.what());
    }
    auto& cam = impl_->fbo->getCamera(*impl_->scene);
    // OpenGL samples pixel i at i + 0.5, OpenCV/TUM at i: shift the principal point so that
    // the images follow the OpenCV convention exactly (verified by tests/render).
    mrpt::img::TCamera gl;
    gl.ncols = uint32_t(sc_.K.width);
    gl.nrows = uint32_t(sc_.K.height);
    gl.fx(sc_.K.fx);
    gl.fy(sc_.K.fy);
    gl.cx(sc_.K.cx + 0.5);
    gl.cy(sc_.K.cy + 0.5);
    cam.setProjectiveFromPinhole(gl);
    cam.set6DOFMode(true);
}

SequenceRenderer::~SequenceRenderer() = default;

RenderedFrame SequenceRenderer::render(std::size_t i) {
    const double t = sc_.elapsed(i);
    RenderedFrame out;
    out.T_wc = cameraPoseAt(sc_.trajectory, t);
    const Eigen::Vector3d eye(out.T_wc.x(), out.T_wc.y(), out.T_wc.z());

    // Each person's planar parts at t: the hand first (it is in front), then the body.
    std::vector<std::vector<PersonPart>> parts(sc_.people.size());
    std::vector<PersonState> state(sc_.people.size());
    for (std::size_t k = 0; k < sc_.people.size(); ++k) {
        state[k] = personStateAt(sc_.people[k], t);
        const auto body = personPhotoPose(sc_.people[k], state[k], eye, impl_->first_eye);
        auto& person = impl_->people[k];
        person.mesh->setPose(body);
        if (person.hand) {
            const auto hand = body + gestureLocalPose(sc_.people[k], state[k], person.width);
            person.hand->setPose(hand);
            parts[k].push_back(personPart(hand, true));
        }
        parts[k].push_back(personPart(body, false));
    }

    auto& cam = impl_->fbo->getCamera(*impl_->scene);
    cam.setPose(out.T_wc);
    mrpt::img::CImage rgb;
    mrpt::math::CMatrixFloat depth;
    impl_->fbo->render_RGBD(*impl_->scene, rgb, depth);

    const auto& K = sc_.K;
    cv::Mat bgr = rgb.asCvMat<cv::Mat>(mrpt::img::DEEP_COPY);
    if (bgr.channels() == 1) cv::cvtColor(bgr, bgr, cv::COLOR_GRAY2BGR);
    out.clean_depth = cv::Mat(K.height, K.width, CV_32FC1);
    for (int v = 0; v < K.height; ++v)
        for (int u = 0; u < K.width; ++u) out.clean_depth.at<float>(v, u) = depth(v, u);
    if (sc_.rgb_noise_sigma > 0) addRgbNoise(bgr, sc_.rgb_noise_sigma, mixSeed(sc_.seed, i, 1));

    out.labels = cv::Mat(K.height, K.width, CV_8UC1, cv::Scalar(0));
    for (std::size_t k = 0; k < sc_.people.size(); ++k) {
        PersonTruth pt = impl_->labelPerson(k, parts[k], out.T_wc, K, out.clean_depth, out.labels);
        pt.name = sc_.people[k].name;
        pt.moving = state[k].moving;
        out.persons.push_back(pt);
    }

    auto& f = out.frame;
    f.index = i;
    f.timestamp = sc_.timeOf(i);
    f.bgr = bgr;
    f.depth = applyDepthNoise(out.clean_depth, sc_.depth_noise, K.fx, mixSeed(sc_.seed, i, 2));
    f.K = K;
    f.depth_scale = 5000.0;
    f.rgb_source = f.depth_source = "synthetic:" + sc_.name + "#" + std::to_string(i);
    return out;
}

}  // namespace devslam::render
