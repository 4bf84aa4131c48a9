// Depthwise and pointwise convolutions for cv::dnn with AVX2/FMA kernels. See the header for
// why they are written by hand. Both compute, per output value, bias + sum(weight * input)
// in float, then the fused activation; only the summation order differs from OpenCV's, so
// outputs agree to float rounding (tests/detect/test_fast_convolution.cpp).
#include <devslam/detect/FastConvolution.h>

#include <opencv2/core/utility.hpp>
#include <opencv2/dnn/all_layers.hpp>
#include <opencv2/dnn/layer.hpp>

#include <immintrin.h>

#include <algorithm>
#include <cstring>
#include <mutex>
#include <set>
#include <string>
#include <vector>

namespace devslam::detect {
namespace {
using cv::dnn::LayerParams;

constexpr int kLanes = 8;  // floats in an AVX register

// The convolutions handled here.
struct Shape {
    enum Kind { Depthwise, Pointwise } kind = Pointwise;
    int k = 1;       // kernel size (square)
    int stride = 1;  // same in x and y
    int pad = 0;     // same on every side
    int cin = 0;
    int cout = 0;
    bool bias = false;  // a second blob holds it
};

// `key` as one int, also when given as a list of equal values (some importers write
// [kh, kw] or four pads); false when it is not an int or the values differ.
bool uniformInt(const LayerParams& p, const std::string& key, int fallback, int& out) {
    if (!p.has(key)) {
        out = fallback;
        return true;
    }
    const cv::dnn::DictValue& v = p.get(key);
    if (!v.isInt() || v.size() < 1) return false;
    out = v.get<int>(0);
    for (int i = 1; i < v.size(); ++i)
        if (v.get<int>(i) != out) return false;
    return true;
}

// The shape of a "Convolution" layer's parameters if this file handles it. Anything not
// understood (dilation, asymmetric or "SAME" padding, other keys) is left to OpenCV.
bool handledShape(const LayerParams& p, Shape& s) {
    static const std::set<std::string> kKnown{"kernel_size", "stride", "pad",      "dilation",
                                              "group",       "num_output", "bias_term"};
    for (auto it = p.begin(); it != p.end(); ++it)
        if (!kKnown.count(it->first)) return false;
    int dilation = 1, group = 1;
    if (!uniformInt(p, "kernel_size", 0, s.k) || !uniformInt(p, "stride", 1, s.stride) ||
        !uniformInt(p, "pad", 0, s.pad) || !uniformInt(p, "dilation", 1, dilation) ||
        !uniformInt(p, "group", 1, group) || !uniformInt(p, "num_output", 0, s.cout))
        return false;
    if (p.blobs.empty() || p.blobs.size() > 2 || dilation != 1 || s.cout <= 0) return false;
    const cv::Mat& w = p.blobs[0];
    if (w.type() != CV_32F || w.dims != 4 || w.size[0] != s.cout || w.size[2] != s.k ||
        w.size[3] != s.k || !w.isContinuous())
        return false;
    // A bias is there when its blob is, as OpenCV's own layer decides (hasBias()): the
    // ONNX importer pushes it without setting "bias_term", the darknet one sets both.
    s.bias = p.blobs.size() >= 2;
    if (s.bias && (p.blobs[1].type() != CV_32F || static_cast<int>(p.blobs[1].total()) != s.cout))
        return false;
    if (!s.bias && p.get<bool>("bias_term", false)) return false;  // promised, not given
    if (group == s.cout && w.size[1] == 1 && s.k % 2 == 1 && s.k <= 7 &&
        (s.stride == 1 || s.stride == 2) && s.pad >= 0 && s.pad < s.k) {
        s.kind = Shape::Depthwise;
        s.cin = s.cout;
        return true;
    }
    if (group == 1 && s.k == 1 && s.stride == 1 && s.pad == 0) {
        s.kind = Shape::Pointwise;
        s.cin = w.size[1];
        return true;
    }
    return false;
}

// ---- kernels -------------------------------------------------------------------------

struct Activation {
    bool on = false;
    float slope = 0.f;  // in [0, 1], so max(x, slope * x) is the leaky ReLU
};

__attribute__((target("avx2,fma"))) inline __m256 activate(__m256 v, const Activation& a) {
    return a.on ? _mm256_max_ps(v, _mm256_mul_ps(v, _mm256_set1_ps(a.slope))) : v;
}

// 8 x 8 transpose: r[i] holds row i on entry and column i on exit.
__attribute__((target("avx2,fma"))) inline void transpose8(__m256 r[8]) {
    const __m256 t0 = _mm256_unpacklo_ps(r[0], r[1]), t1 = _mm256_unpackhi_ps(r[0], r[1]);
    const __m256 t2 = _mm256_unpacklo_ps(r[2], r[3]), t3 = _mm256_unpackhi_ps(r[2], r[3]);
    const __m256 t4 = _mm256_unpacklo_ps(r[4], r[5]), t5 = _mm256_unpackhi_ps(r[4], r[5]);
    const __m256 t6 = _mm256_unpacklo_ps(r[6], r[7]), t7 = _mm256_unpackhi_ps(r[6], r[7]);
    const __m256 u0 = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0));
    const __m256 u1 = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
    const __m256 u2 = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0));
    const __m256 u3 = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2));
    const __m256 u4 = _mm256_shuffle_ps(t4, t6, _MM_SHUFFLE(1, 0, 1, 0));
    const __m256 u5 = _mm256_shuffle_ps(t4, t6, _MM_SHUFFLE(3, 2, 3, 2));
    const __m256 u6 = _mm256_shuffle_ps(t5, t7, _MM_SHUFFLE(1, 0, 1, 0));
    const __m256 u7 = _mm256_shuffle_ps(t5, t7, _MM_SHUFFLE(3, 2, 3, 2));
    r[0] = _mm256_permute2f128_ps(u0, u4, 0x20);
    r[1] = _mm256_permute2f128_ps(u1, u5, 0x20);
    r[2] = _mm256_permute2f128_ps(u2, u6, 0x20);
    r[3] = _mm256_permute2f128_ps(u3, u7, 0x20);
    r[4] = _mm256_permute2f128_ps(u0, u4, 0x31);
    r[5] = _mm256_permute2f128_ps(u1, u5, 0x31);
    r[6] = _mm256_permute2f128_ps(u2, u6, 0x31);
    r[7] = _mm256_permute2f128_ps(u3, u7, 0x31);
}

// Depthwise convolution, 8 channels at a time with one channel per SIMD lane: the group's
// planes are interleaved ([row][column][8 channels], zero padding included), a band of
// rows at a time so that they stay in cache, and each output position is one vector FMA per
// tap. So every row width and stride is as fast as any other (vectorising along a row of 10
// or 20 outputs leaves lanes idle and at stride 2 needs deinterleaving), and no output
// position waits on another: NX positions are summed at once to hide the FMA latency.
struct DepthwiseGroup {
    const float* planes[kLanes];  // input planes of the group's channels (nullptr: none)
    float* out[kLanes];           // output planes (nullptr: none)
    const float* w;               // [tap][8] weights, lane = channel
    const float* bias;            // [8]
};

template <int NX>
__attribute__((target("avx2,fma"))) void depthwisePositions(const float* src, int step,
                                                            const int* offsets, int taps,
                                                            const float* w, const float* bias,
                                                            const Activation& act, float* dst) {
    __m256 acc[NX];
    const __m256 b = _mm256_loadu_ps(bias);
    for (int j = 0; j < NX; ++j) acc[j] = b;
    for (int t = 0; t < taps; ++t) {
        const __m256 wv = _mm256_loadu_ps(w + t * kLanes);
        const float* p = src + offsets[t];
        for (int j = 0; j < NX; ++j)
            acc[j] = _mm256_fmadd_ps(_mm256_loadu_ps(p + j * step), wv, acc[j]);
    }
    for (int j = 0; j < NX; ++j) _mm256_storeu_ps(dst + j * kLanes, activate(acc[j], act));
}

__attribute__((target("avx2,fma"))) void depthwiseGroup(const Shape& s, const DepthwiseGroup& g,
                                                        int h, int w, int oh, int ow,
                                                        const Activation& act) {
    constexpr int kNx = 6;
    using Positions = void (*)(const float*, int, const int*, int, const float*, const float*,
                               const Activation&, float*);
    static constexpr Positions kRest[kNx] = {nullptr,
                                             depthwisePositions<1>,
                                             depthwisePositions<2>,
                                             depthwisePositions<3>,
                                             depthwisePositions<4>,
                                             depthwisePositions<5>};
    const int wp = (ow - 1) * s.stride + s.k;  // padded columns read
    const int row_floats = wp * kLanes;
    // Output rows per band: its interleaved input takes about 64 KiB.
    const int band = std::clamp((16384 / row_floats - s.k) / s.stride + 1, 1, oh);
    thread_local std::vector<float> buf, res;
    buf.resize(static_cast<std::size_t>((band - 1) * s.stride + s.k) * row_floats);
    res.resize(static_cast<std::size_t>(ow) * kLanes);  // [position][8 channels] of a row
    int offsets[7 * 7];
    const int taps = s.k * s.k;
    for (int ky = 0; ky < s.k; ++ky)
        for (int kx = 0; kx < s.k; ++kx) offsets[ky * s.k + kx] = (ky * wp + kx) * kLanes;
    const __m256 zero = _mm256_setzero_ps();

    for (int oy0 = 0; oy0 < oh; oy0 += band) {
        const int oy1 = std::min(oh, oy0 + band);
        const int r0 = oy0 * s.stride;
        const int r1 = (oy1 - 1) * s.stride + s.k;
        for (int r = r0; r < r1; ++r) {  // interleave padded rows r0..r1-1
            float* dst = buf.data() + static_cast<std::ptrdiff_t>(r - r0) * row_floats;
            const int iy = r - s.pad;
            if (iy < 0 || iy >= h) {
                std::fill(dst, dst + row_floats, 0.f);
                continue;
            }
            // columns [0, pad) and [pad + w, wp) are padding
            for (int px = 0; px < std::min(s.pad, wp); ++px)
                _mm256_storeu_ps(dst + px * kLanes, zero);
            for (int px = s.pad + w; px < wp; ++px) _mm256_storeu_ps(dst + px * kLanes, zero);
            const int cols = std::min(w, wp - s.pad);  // input columns read
            int ix = 0;
            for (; ix + kLanes <= cols; ix += kLanes) {
                __m256 v[kLanes];
                for (int c = 0; c < kLanes; ++c)
                    v[c] = g.planes[c] ? _mm256_loadu_ps(g.planes[c] +
                                                         static_cast<std::ptrdiff_t>(iy) * w + ix)
                                       : zero;
                transpose8(v);
                for (int j = 0; j < kLanes; ++j)
                    _mm256_storeu_ps(dst + (s.pad + ix + j) * kLanes, v[j]);
            }
            for (; ix < cols; ++ix)
                for (int c = 0; c < kLanes; ++c)
                    dst[(s.pad + ix) * kLanes + c] =
                        g.planes[c] ? g.planes[c][static_cast<std::ptrdiff_t>(iy) * w + ix] : 0.f;
        }
        for (int oy = oy0; oy < oy1; ++oy) {
            const float* row = buf.data() + static_cast<std::ptrdiff_t>(oy - oy0) * s.stride *
                                                row_floats;
            const int step = s.stride * kLanes;
            int ox = 0;
            for (; ox + kNx <= ow; ox += kNx)
                depthwisePositions<kNx>(row + ox * step, step, offsets, taps, g.w, g.bias, act,
                                        res.data() + ox * kLanes);
            if (ox < ow)  // the row's last 1 to kNx - 1 positions
                kRest[ow - ox](row + ox * step, step, offsets, taps, g.w, g.bias, act,
                               res.data() + ox * kLanes);
            // back to planes
            int x = 0;
            for (; x + kLanes <= ow; x += kLanes) {
                __m256 v[kLanes];
                for (int j = 0; j < kLanes; ++j) v[j] = _mm256_loadu_ps(res.data() + (x + j) * kLanes);
                transpose8(v);
                for (int c = 0; c < kLanes; ++c)
                    if (g.out[c])
                        _mm256_storeu_ps(g.out[c] + static_cast<std::ptrdiff_t>(oy) * ow + x, v[c]);
            }
            for (; x < ow; ++x)
                for (int c = 0; c < kLanes; ++c)
                    if (g.out[c])
                        g.out[c][static_cast<std::ptrdiff_t>(oy) * ow + x] = res[x * kLanes + c];
        }
    }
}

// Pointwise: out[co][p] = bias[co] + sum_ci w[co][ci] * in[ci][p], a matrix product. The
// kernel computes 4 output channels x 24 pixels (12 accumulators) per pass over the input
// channels, with the weights packed as [co / 4][ci][co % 4].
constexpr int kPwRows = 4;
constexpr int kPwCols = 3 * kLanes;

__attribute__((target("avx2,fma"))) inline void storeRow(float* d, const Activation& act,
                                                         __m256 v0, __m256 v1, __m256 v2) {
    _mm256_storeu_ps(d, activate(v0, act));
    _mm256_storeu_ps(d + kLanes, activate(v1, act));
    _mm256_storeu_ps(d + 2 * kLanes, activate(v2, act));
}

// c_v += a_v * w for v = 0, 1, 2 (one output channel, 24 pixels).
__attribute__((target("avx2,fma"))) inline void fmaRow(__m256 a0, __m256 a1, __m256 a2, __m256 w,
                                                       __m256& c0, __m256& c1, __m256& c2) {
    c0 = _mm256_fmadd_ps(a0, w, c0);
    c1 = _mm256_fmadd_ps(a1, w, c1);
    c2 = _mm256_fmadd_ps(a2, w, c2);
}

__attribute__((target("avx2,fma"))) void pointwiseTile(const float* src, std::ptrdiff_t src_stride,
                                                        int cin, const float* packed,
                                                        const float* bias4,
                                                        const Activation& act, float* dst,
                                                        std::ptrdiff_t dst_stride, int rows) {
    // Twelve named accumulators: held in an array, GCC 12 keeps a copy of them on the stack
    // and stores all twelve on every iteration, which halves the speed.
    __m256 c00 = _mm256_set1_ps(bias4[0]), c01 = c00, c02 = c00;
    __m256 c10 = _mm256_set1_ps(bias4[1]), c11 = c10, c12 = c10;
    __m256 c20 = _mm256_set1_ps(bias4[2]), c21 = c20, c22 = c20;
    __m256 c30 = _mm256_set1_ps(bias4[3]), c31 = c30, c32 = c30;
    for (int ci = 0; ci < cin; ++ci) {
        const float* x = src + ci * src_stride;
        const __m256 a0 = _mm256_loadu_ps(x);
        const __m256 a1 = _mm256_loadu_ps(x + kLanes);
        const __m256 a2 = _mm256_loadu_ps(x + 2 * kLanes);
        const float* wp = packed + static_cast<std::ptrdiff_t>(ci) * kPwRows;
        fmaRow(a0, a1, a2, _mm256_broadcast_ss(wp), c00, c01, c02);
        fmaRow(a0, a1, a2, _mm256_broadcast_ss(wp + 1), c10, c11, c12);
        fmaRow(a0, a1, a2, _mm256_broadcast_ss(wp + 2), c20, c21, c22);
        fmaRow(a0, a1, a2, _mm256_broadcast_ss(wp + 3), c30, c31, c32);
    }
    storeRow(dst, act, c00, c01, c02);
    if (rows > 1) storeRow(dst + dst_stride, act, c10, c11, c12);
    if (rows > 2) storeRow(dst + 2 * dst_stride, act, c20, c21, c22);
    if (rows > 3) storeRow(dst + 3 * dst_stride, act, c30, c31, c32);
}

// Rows [0, cin) x columns [0, cols) of `src` (rows `stride` apart) into `dst` as cin rows of
// kPwCols, zero-padded. Inline copies: with 8-16 input channels a library memcpy call per
// row of 24 floats cost about as much as the multiplication.
__attribute__((target("avx2,fma"))) void copyPanel(const float* src, std::ptrdiff_t stride,
                                                    int cin, int cols, float* dst) {
    if (cols == kPwCols) {
        for (int ci = 0; ci < cin; ++ci, src += stride, dst += kPwCols) {
            _mm256_storeu_ps(dst, _mm256_loadu_ps(src));
            _mm256_storeu_ps(dst + kLanes, _mm256_loadu_ps(src + kLanes));
            _mm256_storeu_ps(dst + 2 * kLanes, _mm256_loadu_ps(src + 2 * kLanes));
        }
        return;
    }
    for (int ci = 0; ci < cin; ++ci, src += stride, dst += kPwCols) {
        std::memcpy(dst, src, sizeof(float) * static_cast<std::size_t>(cols));
        std::fill(dst + cols, dst + kPwCols, 0.f);
    }
}

// ---- the layer -------------------------------------------------------------------------

class FastConvolutionLayer final : public cv::dnn::Layer {
  public:
    FastConvolutionLayer(const LayerParams& params, const Shape& shape)
        : Layer(params), shape_(shape) {
        resetWeights();
    }

    // OpenCV calls this each time it sets the network up (a first forward, another input
    // size), before it fuses layers into this one again: what the last fusion folded in
    // goes, as OpenCV's own convolution rebuilds its weights from its blobs. (The batch norm
    // was fused twice; with a ReLU, fusion was refused and the batch norm ran again.)
    void finalize(cv::InputArrayOfArrays, cv::OutputArrayOfArrays) override { resetWeights(); }

    bool getMemoryShapes(const std::vector<cv::dnn::MatShape>& inputs, int /*requiredOutputs*/,
                         std::vector<cv::dnn::MatShape>& outputs,
                         std::vector<cv::dnn::MatShape>& /*internals*/) const override {
        CV_Assert(inputs.size() == 1 && inputs[0].size() == 4);
        const auto& in = inputs[0];
        if (in[1] != shape_.cin)
            CV_Error(cv::Error::StsBadArg, "convolution '" + name + "' expects " +
                                               std::to_string(shape_.cin) +
                                               " input channels, got " + std::to_string(in[1]));
        const int oh = (in[2] + 2 * shape_.pad - shape_.k) / shape_.stride + 1;
        const int ow = (in[3] + 2 * shape_.pad - shape_.k) / shape_.stride + 1;
        CV_Assert(oh > 0 && ow > 0);
        outputs.assign(1, cv::dnn::MatShape{in[0], shape_.cout, oh, ow});
        return false;
    }

    bool tryFuse(cv::Ptr<cv::dnn::Layer>& top) override {
        if (act_.on) return false;  // a scale after the activation cannot move before it
        cv::Mat scale, shift;
        top->getScaleShift(scale, shift);
        if (scale.empty() && shift.empty()) return false;
        const auto fits = [&](const cv::Mat& m) {
            return m.empty() || (m.type() == CV_32F && m.isContinuous() &&
                                 (static_cast<int>(m.total()) == shape_.cout || m.total() == 1));
        };
        if (!fits(scale) || !fits(shift)) return false;
        const std::size_t per_out = weights_.size() / static_cast<std::size_t>(shape_.cout);
        for (int co = 0; co < shape_.cout; ++co) {
            const float a = scale.empty() ? 1.f : scale.ptr<float>()[scale.total() == 1 ? 0 : co];
            const float b = shift.empty() ? 0.f : shift.ptr<float>()[shift.total() == 1 ? 0 : co];
            for (std::size_t i = 0; i < per_out; ++i) weights_[co * per_out + i] *= a;
            bias_[co] = bias_[co] * a + b;
        }
        pack();
        return true;
    }

    bool setActivation(const cv::Ptr<cv::dnn::ActivationLayer>& layer) override {
        const auto relu = layer.dynamicCast<cv::dnn::ReLULayer>();
        if (relu.empty() || !(relu->negativeSlope >= 0.f && relu->negativeSlope <= 1.f))
            return false;
        act_ = {true, relu->negativeSlope};
        return true;
    }

    void forward(cv::InputArrayOfArrays inputs_arr, cv::OutputArrayOfArrays outputs_arr,
                 cv::OutputArrayOfArrays internals_arr) override {
        if (inputs_arr.depth() != CV_32F) {  // half floats: converted, then back here
            forward_fallback(inputs_arr, outputs_arr, internals_arr);
            return;
        }
        std::vector<cv::Mat> inputs, outputs;
        inputs_arr.getMatVector(inputs);
        outputs_arr.getMatVector(outputs);
        const cv::Mat& x = inputs[0];
        cv::Mat& y = outputs[0];
        CV_Assert(x.isContinuous() && y.isContinuous() && x.dims == 4 && y.dims == 4);
        if (shape_.kind == Shape::Depthwise)
            forwardDepthwise(x, y);
        else
            forwardPointwise(x, y);
    }

  private:
    // The weights and bias as read (Layer::blobs keeps them), no activation fused.
    void resetWeights() {
        const cv::Mat& w = blobs[0];
        weights_.assign(w.ptr<float>(), w.ptr<float>() + w.total());
        bias_.assign(static_cast<std::size_t>(shape_.cout), 0.f);
        if (shape_.bias) std::copy_n(blobs[1].ptr<float>(), shape_.cout, bias_.begin());
        act_ = {};
        pack();
    }

    // Weights in the kernels' layouts, zeros past the last channel: see each branch.
    void pack() {
        if (shape_.kind == Shape::Depthwise) {  // [channel / 8][tap][channel % 8]
            const int groups = (shape_.cout + kLanes - 1) / kLanes;
            const int taps = shape_.k * shape_.k;
            packed_.assign(static_cast<std::size_t>(groups) * taps * kLanes, 0.f);
            packed_bias_.assign(static_cast<std::size_t>(groups) * kLanes, 0.f);
            for (int ch = 0; ch < shape_.cout; ++ch) {
                const int g = ch / kLanes, lane = ch % kLanes;
                for (int t = 0; t < taps; ++t)
                    packed_[(static_cast<std::size_t>(g) * taps + t) * kLanes + lane] =
                        weights_[static_cast<std::size_t>(ch) * taps + t];
                packed_bias_[static_cast<std::size_t>(g) * kLanes + lane] = bias_[ch];
            }
            return;
        }
        const int blocks = (shape_.cout + kPwRows - 1) / kPwRows;
        packed_.assign(static_cast<std::size_t>(blocks) * shape_.cin * kPwRows, 0.f);
        packed_bias_.assign(static_cast<std::size_t>(blocks) * kPwRows, 0.f);
        for (int co = 0; co < shape_.cout; ++co) {
            const int b = co / kPwRows, j = co % kPwRows;
            for (int ci = 0; ci < shape_.cin; ++ci)
                packed_[(static_cast<std::size_t>(b) * shape_.cin + ci) * kPwRows + j] =
                    weights_[static_cast<std::size_t>(co) * shape_.cin + ci];
            packed_bias_[static_cast<std::size_t>(b) * kPwRows + j] = bias_[co];
        }
    }

    static int stripes(int tasks) { return std::min(tasks, 8 * std::max(1, cv::getNumThreads())); }

    void forwardDepthwise(const cv::Mat& x, cv::Mat& y) const {
        const int n = x.size[0], c = x.size[1], h = x.size[2], w = x.size[3];
        const int oh = y.size[2], ow = y.size[3];
        const int groups = (c + kLanes - 1) / kLanes;
        const float* in = x.ptr<float>();
        float* out = y.ptr<float>();
        cv::parallel_for_(
            cv::Range(0, n * groups),
            [&](const cv::Range& r) {
                for (int t = r.start; t < r.end; ++t) {
                    const int img = t / groups, g = t % groups;
                    DepthwiseGroup dg{};
                    for (int lane = 0; lane < kLanes; ++lane) {
                        const int ch = g * kLanes + lane;
                        if (ch >= c) break;
                        const std::ptrdiff_t plane = static_cast<std::ptrdiff_t>(img) * c + ch;
                        dg.planes[lane] = in + plane * h * w;
                        dg.out[lane] = out + plane * oh * ow;
                    }
                    dg.w = packed_.data() + static_cast<std::ptrdiff_t>(g) * shape_.k * shape_.k *
                                                kLanes;
                    dg.bias = packed_bias_.data() + static_cast<std::ptrdiff_t>(g) * kLanes;
                    depthwiseGroup(shape_, dg, h, w, oh, ow, act_);
                }
            },
            stripes(n * groups));
    }

    void forwardPointwise(const cv::Mat& x, cv::Mat& y) const {
        const int n = x.size[0], cin = shape_.cin, cout = shape_.cout;
        const int p = x.size[2] * x.size[3];
        const int tiles = (p + kPwCols - 1) / kPwCols;
        const int blocks = (cout + kPwRows - 1) / kPwRows;
        // Tiles per task: their input panel takes about 32 KiB.
        const int chunk = std::clamp(8192 / (cin * kPwCols), 1, tiles);
        const int chunks = (tiles + chunk - 1) / chunk;
        const float* in = x.ptr<float>();
        float* out = y.ptr<float>();
        // A task copies the input of `chunk` tiles into a contiguous panel, tile after tile
        // (rows of the input tensor lie a whole plane apart, often a multiple of 4 KiB, so
        // reading them in place thrashes one set of the L1 cache), then computes each block
        // of output channels over all its tiles: 4 output planes written along a run of
        // pixels, not 4 x 24 pixels in each of all planes in turn.
        cv::parallel_for_(
            cv::Range(0, n * chunks),
            [&](const cv::Range& r) {
                thread_local std::vector<float> panel, dst_tmp;
                panel.resize(static_cast<std::size_t>(chunk) * cin * kPwCols);
                dst_tmp.resize(static_cast<std::size_t>(kPwRows) * kPwCols);
                for (int t = r.start; t < r.end; ++t) {
                    const int img = t / chunks;
                    const int tile0 = (t % chunks) * chunk;
                    const int ntiles = std::min(chunk, tiles - tile0);
                    const float* src = in + static_cast<std::ptrdiff_t>(img) * cin * p;
                    for (int i = 0; i < ntiles; ++i) {
                        const int p0 = (tile0 + i) * kPwCols;
                        const int cols = std::min(kPwCols, p - p0);
                        float* dst = panel.data() + static_cast<std::ptrdiff_t>(i) * cin * kPwCols;
                        copyPanel(src + p0, p, cin, cols, dst);
                    }
                    for (int b = 0; b < blocks; ++b) {
                        const int rows = std::min(kPwRows, cout - b * kPwRows);
                        const float* wp =
                            packed_.data() + static_cast<std::ptrdiff_t>(b) * cin * kPwRows;
                        const float* bp = packed_bias_.data() + b * kPwRows;
                        float* dst_block =
                            out + (static_cast<std::ptrdiff_t>(img) * cout + b * kPwRows) * p;
                        for (int i = 0; i < ntiles; ++i) {
                            const int p0 = (tile0 + i) * kPwCols;
                            const int cols = std::min(kPwCols, p - p0);
                            const float* tile_in =
                                panel.data() + static_cast<std::ptrdiff_t>(i) * cin * kPwCols;
                            if (cols == kPwCols) {
                                pointwiseTile(tile_in, kPwCols, cin, wp, bp, act_, dst_block + p0,
                                              p, rows);
                                continue;
                            }
                            // A partial tile: stores stay inside the output tensor.
                            pointwiseTile(tile_in, kPwCols, cin, wp, bp, act_, dst_tmp.data(),
                                          kPwCols, rows);
                            for (int j = 0; j < rows; ++j)
                                std::memcpy(dst_block + static_cast<std::ptrdiff_t>(j) * p + p0,
                                            dst_tmp.data() + static_cast<std::ptrdiff_t>(j) * kPwCols,
                                            sizeof(float) * static_cast<std::size_t>(cols));
                        }
                    }
                }
            },
            stripes(n * chunks));
    }

    Shape shape_;
    std::vector<float> weights_;  // [cout][cin / group][k][k], batch norm fused in
    std::vector<float> bias_;     // [cout], batch norm fused in
    Activation act_;
    std::vector<float> packed_, packed_bias_;  // see pack()
};

cv::Ptr<cv::dnn::Layer> createConvolution(LayerParams& params) {
    Shape shape;
    if (handledShape(params, shape)) return cv::makePtr<FastConvolutionLayer>(params, shape);
    return cv::dnn::ConvolutionLayer::create(params);
}

std::mutex& registrationMutex() {
    static std::mutex m;
    return m;
}

}  // namespace

bool fastConvolutionsSupported() {
    return cv::checkHardwareSupport(CV_CPU_AVX2) && cv::checkHardwareSupport(CV_CPU_FMA3);
}

cv::dnn::Net withFastConvolutions(const std::function<cv::dnn::Net()>& read) {
    if (!fastConvolutionsSupported()) return read();
    std::lock_guard<std::mutex> lock(registrationMutex());
    // Layers are created lazily by cv::dnn, so all are created here, while registered.
    struct Registration {
        Registration() { cv::dnn::LayerFactory::registerLayer("Convolution", createConvolution); }
        ~Registration() { cv::dnn::LayerFactory::unregisterLayer("Convolution"); }
        Registration(const Registration&) = delete;
        Registration& operator=(const Registration&) = delete;
    } registration;
    cv::dnn::Net net = read();
    for (const auto& name : net.getLayerNames()) (void)net.getLayer(net.getLayerId(name));
    return net;
}

bool isFastConvolution(const cv::Ptr<cv::dnn::Layer>& layer) {
    return !layer.dynamicCast<FastConvolutionLayer>().empty();
}

int countFastConvolutions(cv::dnn::Net& net) {
    int n = 0;
    for (const auto& name : net.getLayerNames())
        n += isFastConvolution(net.getLayer(net.getLayerId(name))) ? 1 : 0;
    return n;
}

}  // namespace devslam::detect
