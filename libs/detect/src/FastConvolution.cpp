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

int roundUp(int v, int m) { return (v + m - 1) / m * m; }

// The convolutions handled here.
struct Shape {
    enum Kind { Depthwise, Pointwise } kind = Pointwise;
    int k = 1;       // kernel size (square)
    int stride = 1;  // same in x and y
    int pad = 0;     // same on every side
    int cin = 0;
    int cout = 0;
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
    if (p.blobs.empty() || dilation != 1 || s.cout <= 0) return false;
    const cv::Mat& w = p.blobs[0];
    if (w.type() != CV_32F || w.dims != 4 || w.size[0] != s.cout || w.size[2] != s.k ||
        w.size[3] != s.k || !w.isContinuous())
        return false;
    const bool bias = p.get<bool>("bias_term", false);
    if (bias && (p.blobs.size() < 2 || p.blobs[1].type() != CV_32F ||
                 static_cast<int>(p.blobs[1].total()) != s.cout))
        return false;
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

// Depthwise convolution of one channel. The zero-padded input is copied, a band of rows at
// a time (so that it stays in the L1 cache), split by column phase: column c of padded row r
// goes to phases[((r - first row) * stride + c % stride) * pw + c / stride], so that every tap
// reads contiguous memory also at stride 2. `offsets` are the taps' positions there relative
// to an output's first tap. NB blocks of 8 outputs are summed at once to hide the FMA
// latency: along a row (`base` + 8 b) or, for rows narrower than that, across rows.
template <int NB>
__attribute__((target("avx2,fma"))) void depthwiseRowBlocks(const float* base, const int* offsets,
                                                             int taps, const float* w, float bias,
                                                             const Activation& act, float* dst) {
    __m256 acc[NB];
    for (int b = 0; b < NB; ++b) acc[b] = _mm256_set1_ps(bias);
    for (int t = 0; t < taps; ++t) {
        const float* src = base + offsets[t];
        const __m256 wv = _mm256_set1_ps(w[t]);
        for (int b = 0; b < NB; ++b)
            acc[b] = _mm256_fmadd_ps(_mm256_loadu_ps(src + b * kLanes), wv, acc[b]);
    }
    for (int b = 0; b < NB; ++b) _mm256_storeu_ps(dst + b * kLanes, activate(acc[b], act));
}

template <int NB>
__attribute__((target("avx2,fma"))) void depthwiseScattered(const float* const* bases,
                                                             const int* offsets, int taps,
                                                             const float* w, float bias,
                                                             const Activation& act,
                                                             float* const* dsts) {
    __m256 acc[NB];
    for (int b = 0; b < NB; ++b) acc[b] = _mm256_set1_ps(bias);
    for (int t = 0; t < taps; ++t) {
        const __m256 wv = _mm256_set1_ps(w[t]);
        for (int b = 0; b < NB; ++b)
            acc[b] = _mm256_fmadd_ps(_mm256_loadu_ps(bases[b] + offsets[t]), wv, acc[b]);
    }
    for (int b = 0; b < NB; ++b) _mm256_storeu_ps(dsts[b], activate(acc[b], act));
}

// Padded row r of the input into its phase rows at `dst`; `row` is scratch of at least
// max(stride * pw, w + 2 pad) floats whose padding columns are zero.
__attribute__((target("avx2,fma"))) void copyPhases(const float* in, int h, int w, int pad,
                                                     int stride, int pw, int r, float* row,
                                                     float* dst) {
    const int iy = r - pad;
    if (iy < 0 || iy >= h) {
        std::fill(dst, dst + static_cast<std::ptrdiff_t>(stride) * pw, 0.f);
        return;
    }
    const float* src = in + static_cast<std::ptrdiff_t>(iy) * w;
    if (stride == 1) {
        std::fill(dst, dst + pad, 0.f);
        std::memcpy(dst + pad, src, sizeof(float) * static_cast<std::size_t>(w));
        std::fill(dst + pad + w, dst + pw, 0.f);
        return;
    }
    // stride 2: even columns to phase 0, odd ones to phase 1
    std::memcpy(row + pad, src, sizeof(float) * static_cast<std::size_t>(w));
    float* even = dst;
    float* odd = dst + pw;
    int j = 0;
    for (; j + kLanes <= pw; j += kLanes) {
        const __m256 a = _mm256_loadu_ps(row + 2 * j);
        const __m256 b = _mm256_loadu_ps(row + 2 * j + kLanes);
        // per 128-bit lane: a0 a2 b0 b2 | a4 a6 b4 b6 -> reorder the 64-bit pairs
        const __m256 e = _mm256_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0));
        const __m256 o = _mm256_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1));
        _mm256_storeu_ps(even + j, _mm256_castpd_ps(_mm256_permute4x64_pd(
                                       _mm256_castps_pd(e), _MM_SHUFFLE(3, 1, 2, 0))));
        _mm256_storeu_ps(odd + j, _mm256_castpd_ps(_mm256_permute4x64_pd(
                                      _mm256_castps_pd(o), _MM_SHUFFLE(3, 1, 2, 0))));
    }
    for (; j < pw; ++j) {
        even[j] = row[2 * j];
        odd[j] = row[2 * j + 1];
    }
}

__attribute__((target("avx2,fma"))) void depthwiseChannel(const Shape& s, const float* in, int h,
                                                          int w, float* out, int oh, int ow,
                                                          const float* weights, float bias,
                                                          const Activation& act) {
    constexpr int kGroup = 4;
    const int pw = roundUp(ow, kLanes) + (s.k - 1) / s.stride + 1;  // phase row length read
    const int phase_row = s.stride * pw;          // floats per padded input row
    const std::ptrdiff_t out_step = static_cast<std::ptrdiff_t>(s.stride) * phase_row;
    // Output rows per band: its input rows take about 16 KiB.
    const int band = std::clamp((4096 / phase_row - s.k) / s.stride + 1, 1, oh);
    const int band_rows = (band - 1) * s.stride + s.k;
    thread_local std::vector<float> phases, row, tmp;
    phases.resize(static_cast<std::size_t>(band_rows) * phase_row);
    row.assign(static_cast<std::size_t>(std::max(phase_row, w + 2 * s.pad)), 0.f);
    tmp.resize(kGroup * kLanes);
    // Tap (ky, kx) of output (oy, ox) reads padded row oy * stride + ky, column
    // ox * stride + kx, i.e. phase kx % stride at ox + kx / stride.
    int offsets[7 * 7];
    const int taps = s.k * s.k;
    for (int ky = 0; ky < s.k; ++ky)
        for (int kx = 0; kx < s.k; ++kx)
            offsets[ky * s.k + kx] = ky * phase_row + (kx % s.stride) * pw + kx / s.stride;

    // Narrow rows: blocks gathered across rows. A block that ends past its row is computed
    // into `tmp` and copied, here and below: past the row is the next row or the next
    // channel, which another thread may be writing.
    const float* bases[kGroup];
    float* dsts[kGroup];
    float* partial_dst[kGroup];
    int partial_len[kGroup];
    int n = 0;
    const auto flush = [&] {
        switch (n) {
            case 4: depthwiseScattered<4>(bases, offsets, taps, weights, bias, act, dsts); break;
            case 3: depthwiseScattered<3>(bases, offsets, taps, weights, bias, act, dsts); break;
            case 2: depthwiseScattered<2>(bases, offsets, taps, weights, bias, act, dsts); break;
            case 1: depthwiseScattered<1>(bases, offsets, taps, weights, bias, act, dsts); break;
            default: break;
        }
        for (int b = 0; b < n; ++b)
            if (partial_len[b] > 0)
                std::memcpy(partial_dst[b], dsts[b],
                            sizeof(float) * static_cast<std::size_t>(partial_len[b]));
        n = 0;
    };

    for (int oy0 = 0; oy0 < oh; oy0 += band) {
        const int oy1 = std::min(oh, oy0 + band);
        const int r0 = oy0 * s.stride;
        for (int r = r0; r < (oy1 - 1) * s.stride + s.k; ++r)
            copyPhases(in, h, w, s.pad, s.stride, pw, r, row.data(),
                       phases.data() + static_cast<std::ptrdiff_t>(r - r0) * phase_row);
        for (int oy = oy0; oy < oy1; ++oy) {
            const float* base = phases.data() + (oy - oy0) * out_step;
            float* yrow = out + static_cast<std::ptrdiff_t>(oy) * ow;
            if (ow < kGroup * kLanes) {
                for (int ox = 0; ox < ow; ox += kLanes) {
                    const bool partial = ox + kLanes > ow;
                    bases[n] = base + ox;
                    partial_len[n] = partial ? ow - ox : 0;
                    partial_dst[n] = yrow + ox;
                    dsts[n] = partial ? tmp.data() + n * kLanes : yrow + ox;
                    if (++n == kGroup) flush();
                }
                continue;
            }
            int ox = 0;
            for (; ox + kGroup * kLanes <= ow; ox += kGroup * kLanes)
                depthwiseRowBlocks<4>(base + ox, offsets, taps, weights, bias, act, yrow + ox);
            switch ((ow - ox) / kLanes) {
                case 3:
                    depthwiseRowBlocks<3>(base + ox, offsets, taps, weights, bias, act, yrow + ox);
                    break;
                case 2:
                    depthwiseRowBlocks<2>(base + ox, offsets, taps, weights, bias, act, yrow + ox);
                    break;
                case 1:
                    depthwiseRowBlocks<1>(base + ox, offsets, taps, weights, bias, act, yrow + ox);
                    break;
                default:
                    break;
            }
            ox += (ow - ox) / kLanes * kLanes;
            if (ox < ow) {
                depthwiseRowBlocks<1>(base + ox, offsets, taps, weights, bias, act, tmp.data());
                std::memcpy(yrow + ox, tmp.data(), sizeof(float) * static_cast<std::size_t>(ow - ox));
            }
        }
        flush();  // the band's phases are overwritten next
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
        __m256 w = _mm256_broadcast_ss(wp);
        c00 = _mm256_fmadd_ps(a0, w, c00);
        c01 = _mm256_fmadd_ps(a1, w, c01);
        c02 = _mm256_fmadd_ps(a2, w, c02);
        w = _mm256_broadcast_ss(wp + 1);
        c10 = _mm256_fmadd_ps(a0, w, c10);
        c11 = _mm256_fmadd_ps(a1, w, c11);
        c12 = _mm256_fmadd_ps(a2, w, c12);
        w = _mm256_broadcast_ss(wp + 2);
        c20 = _mm256_fmadd_ps(a0, w, c20);
        c21 = _mm256_fmadd_ps(a1, w, c21);
        c22 = _mm256_fmadd_ps(a2, w, c22);
        w = _mm256_broadcast_ss(wp + 3);
        c30 = _mm256_fmadd_ps(a0, w, c30);
        c31 = _mm256_fmadd_ps(a1, w, c31);
        c32 = _mm256_fmadd_ps(a2, w, c32);
    }
    storeRow(dst, act, c00, c01, c02);
    if (rows > 1) storeRow(dst + dst_stride, act, c10, c11, c12);
    if (rows > 2) storeRow(dst + 2 * dst_stride, act, c20, c21, c22);
    if (rows > 3) storeRow(dst + 3 * dst_stride, act, c30, c31, c32);
}

// ---- the layer -------------------------------------------------------------------------

class FastConvolutionLayer final : public cv::dnn::Layer {
  public:
    FastConvolutionLayer(const LayerParams& params, const Shape& shape)
        : Layer(params), shape_(shape) {
        const cv::Mat& w = params.blobs[0];
        weights_.assign(w.ptr<float>(), w.ptr<float>() + w.total());
        bias_.assign(static_cast<std::size_t>(shape_.cout), 0.f);
        if (params.get<bool>("bias_term", false))
            std::copy_n(params.blobs[1].ptr<float>(), shape_.cout, bias_.begin());
        pack();
    }

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
    // Pointwise weights in blocks of kPwRows output channels, zero rows past the last one.
    void pack() {
        if (shape_.kind != Shape::Pointwise) return;
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
        const int kk = shape_.k * shape_.k;
        const float* in = x.ptr<float>();
        float* out = y.ptr<float>();
        cv::parallel_for_(
            cv::Range(0, n * c),
            [&](const cv::Range& r) {
                for (int t = r.start; t < r.end; ++t) {
                    const int ch = t % c;
                    depthwiseChannel(shape_, in + static_cast<std::ptrdiff_t>(t) * h * w, h, w,
                                     out + static_cast<std::ptrdiff_t>(t) * oh * ow, oh, ow,
                                     weights_.data() + static_cast<std::ptrdiff_t>(ch) * kk,
                                     bias_[ch], act_);
                }
            },
            stripes(n * c));
    }

    void forwardPointwise(const cv::Mat& x, cv::Mat& y) const {
        const int n = x.size[0], cin = shape_.cin, cout = shape_.cout;
        const int p = x.size[2] * x.size[3];
        const int tiles = (p + kPwCols - 1) / kPwCols;
        const int blocks = (cout + kPwRows - 1) / kPwRows;
        const float* in = x.ptr<float>();
        float* out = y.ptr<float>();
        // One task per tile of pixels: its input is copied once into a contiguous panel
        // (rows of the input tensor lie a whole plane apart, often a multiple of 4 KiB, so
        // reading them in place thrashes one set of the L1 cache) and then multiplied by
        // every block of output channels.
        cv::parallel_for_(
            cv::Range(0, n * tiles),
            [&](const cv::Range& r) {
                thread_local std::vector<float> panel, dst_tmp;
                panel.resize(static_cast<std::size_t>(cin) * kPwCols);
                dst_tmp.resize(static_cast<std::size_t>(kPwRows) * kPwCols);
                for (int t = r.start; t < r.end; ++t) {
                    const int tile = t % tiles;
                    const int img = t / tiles;
                    const int p0 = tile * kPwCols;
                    const int cols = std::min(kPwCols, p - p0);
                    const float* src = in + static_cast<std::ptrdiff_t>(img) * cin * p + p0;
                    if (cols < kPwCols) std::fill(panel.begin(), panel.end(), 0.f);
                    for (int ci = 0; ci < cin; ++ci)
                        std::memcpy(panel.data() + static_cast<std::ptrdiff_t>(ci) * kPwCols,
                                    src + static_cast<std::ptrdiff_t>(ci) * p,
                                    sizeof(float) * static_cast<std::size_t>(cols));
                    for (int b = 0; b < blocks; ++b) {
                        const int rows = std::min(kPwRows, cout - b * kPwRows);
                        float* dst = out +
                                     (static_cast<std::ptrdiff_t>(img) * cout + b * kPwRows) * p +
                                     p0;
                        const float* wp =
                            packed_.data() + static_cast<std::ptrdiff_t>(b) * cin * kPwRows;
                        const float* bp = packed_bias_.data() + b * kPwRows;
                        if (cols == kPwCols) {
                            pointwiseTile(panel.data(), kPwCols, cin, wp, bp, act_, dst, p, rows);
                            continue;
                        }
                        // A partial tile: stores stay inside the output tensor.
                        pointwiseTile(panel.data(), kPwCols, cin, wp, bp, act_, dst_tmp.data(),
                                      kPwCols, rows);
                        for (int j = 0; j < rows; ++j)
                            std::memcpy(dst + static_cast<std::ptrdiff_t>(j) * p,
                                        dst_tmp.data() + static_cast<std::ptrdiff_t>(j) * kPwCols,
                                        sizeof(float) * static_cast<std::size_t>(cols));
                    }
                }
            },
            stripes(n * tiles));
    }

    Shape shape_;
    std::vector<float> weights_;  // [cout][cin / group][k][k], batch norm fused in
    std::vector<float> bias_;     // [cout], batch norm fused in
    Activation act_;
    std::vector<float> packed_, packed_bias_;  // pointwise only, see pack()
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
