// CPU fast path of one SVGF à-trous level. Same math as svgf::Atrous (the tap weight, the depth
// and normal stops, fastLog/fastExp and the luminance stop are the shared functions of
// svgf_atrous.h / svgf_common.h, and every pixel sums its taps in the functor's order), organised
// for SIMD as src/cpu/eaw_cpu.cpp organises EAW: TBB over row blocks, and for each of the 5 tap
// rows a contiguous, branch-free x loop over the interior columns with the 5 taps of that row
// unrolled. Columns within 2·step of the left/right border run one loop per tap over the columns
// where that tap is inside the image. The generic functor's `continue`s (tap outside, empty pixel,
// across an edge) become weight-0 selects, which add exactly nothing to the sums as long as the
// dropped tap's illumination and variance are finite (0 · Inf = NaN): the pipeline guarantees it
// (Demodulate replaces non-finite colour and clamps to ±kMaxIllum, every later stage takes
// weighted means of those values).
//
// Where the time went before (scalar functor, 512²: ~24 ms per level on 2 cores):
// - logf per tap in the normal stop: now the polynomial fastLog, also used by the GPU;
// - the 3x3 prefiltered variance and the luminance stop's 1/(σ_l sqrt(g) + ε) recomputed with
//   branches for every pixel: now once per row into a buffer, the interior branch-free;
// - branches per tap, which kept GCC from vectorising anything: now selects (selectF);
// - as for EAW, tap loads go through the centre row's plane pointers plus one row offset, and the
//   same row loops are compiled for AVX2 and for AVX-512 (chosen at run time, cpu/cpu_simd.h).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstddef>
#include <vector>

#include "core/parallel.h"
#include "cpu/cpu_simd.h"
#include "filters/filter_math.h"
#include "filters/svgf_atrous.h"

namespace atrous::svgf {

bool& svgfCpuFastPath() {
    static bool enabled = true;
    return enabled;
}

bool& svgfCpuAvx512() {
    static bool enabled = cpuHasAvx512();
    return enabled;
}

namespace {

// Per-task row buffers, indexed by x: the luminance stop of the output row and the five sums.
struct RowBuffers {
    std::vector<float> invLum, sw, sr, sg, sb, sv;
    explicit RowBuffers(int n) : invLum(n), sw(n), sr(n), sg(n), sb(n), sv(n) {}
};

// One tap (pixel offset I·step along x, tap row already in dRow) of the output pixel x, added to
// the running sums sw, sr, sg, sb, sv. GEO: false for the centre tap, whose geometry log-weight is
// 0 by definition (as in the functor). Needs the centre values lp, zp, npx/y/z, gx, gy, il and dy.
// Plain floats only: a Vec3 constructed in the loop body is addressable when `omp simd` is lowered
// (before inlining), becomes a per-lane array, and the loop is not vectorised.
#define ATROUS_SVGF_TAP(I, GEO)                                                                  \
    {                                                                                            \
        const ptrdiff_t q = ptrdiff_t(x) + (I)*s + dRow;                                         \
        const float qr = pr[q], qg = pg[q], qb = pb[q];                                          \
        const float lwGeo =                                                                      \
            (GEO) ? atrousGeometryLogWeightSel(zp, pz[q], gx, gy, npx, npy, npz, pnx[q], pny[q], \
                                               pnz[q], float((I)*s), dy, sigmaZ, sigmaN)         \
                  : 0.0f;                                                                        \
        const float wq =                                                                         \
            atrousTapWeight(hy * b3Tap(I), lwGeo, lp, atrousLuminance(qr, qg, qb), il, plen[q]); \
        sr = fmaf(wq, qr, sr);                                                                   \
        sg = fmaf(wq, qg, sg);                                                                   \
        sb = fmaf(wq, qb, sb);                                                                   \
        sv = fmaf(wq * wq, pv[q], sv);                                                           \
        sw += wq;                                                                                \
    }

// The centre values of pixel x, and the running sums loaded from the row buffers.
#define ATROUS_SVGF_CENTRE                                         \
    const float lp = atrousLuminance(pr[x], pg[x], pb[x]);         \
    const float zp = pz[x], gx = pgx[x], gy = pgy[x], il = pil[x]; \
    const float npx = pnx[x], npy = pny[x], npz = pnz[x];          \
    float sw = aw[x], sr = ar[x], sg = ag[x], sb = ab[x], sv = av[x];

#define ATROUS_SVGF_STORE \
    aw[x] = sw;           \
    ar[x] = sr;           \
    ag[x] = sg;           \
    ab[x] = sb;           \
    av[x] = sv;

// Rows [y0, y1) of one level. Always inlined into the per-ISA wrappers below, which decide the
// vector width.
ATROUS_FORCE_INLINE inline void levelRowsBody(const Atrous& f, int y0, int y1) {
    const int w = f.illum.width, h = f.illum.height;
    const int s = f.step;
    const int x0 = s * 2 < w ? s * 2 : w;
    const int x1 = w - s * 2 > x0 ? w - s * 2 : x0;
    const float sigmaL = f.sigmaL, sigmaN = f.sigmaN, sigmaZ = f.sigmaZ;
    RowBuffers buf(w);
    float* ATROUS_RESTRICT pil = buf.invLum.data();
    float* ATROUS_RESTRICT aw = buf.sw.data();
    float* ATROUS_RESTRICT ar = buf.sr.data();
    float* ATROUS_RESTRICT ag = buf.sg.data();
    float* ATROUS_RESTRICT ab = buf.sb.data();
    float* ATROUS_RESTRICT av = buf.sv.data();
    const float* ATROUS_RESTRICT var = f.variance.channel(0);

    for (int y = y0; y < y1; ++y) {
        const size_t rowP = size_t(y) * w;
        // Luminance stop of this row: g3x3(var) in the functor's summation order (its weights sum
        // to exactly 1 inside, so the division by Σk is a no-op there); the border through the
        // functor's own renormalised version.
        if (y > 0 && y < h - 1 && w > 2) {
            const float* ATROUS_RESTRICT vm = var + rowP - w;
            const float* ATROUS_RESTRICT v0 = var + rowP;
            const float* ATROUS_RESTRICT vp = var + rowP + w;
#pragma omp simd
            for (int x = 1; x < w - 1; ++x) {
                float sum = 0.0f;
                sum = fmaf(0.0625f, vm[x - 1], sum);
                sum = fmaf(0.125f, vm[x], sum);
                sum = fmaf(0.0625f, vm[x + 1], sum);
                sum = fmaf(0.125f, v0[x - 1], sum);
                sum = fmaf(0.25f, v0[x], sum);
                sum = fmaf(0.125f, v0[x + 1], sum);
                sum = fmaf(0.0625f, vp[x - 1], sum);
                sum = fmaf(0.125f, vp[x], sum);
                sum = fmaf(0.0625f, vp[x + 1], sum);
                pil[x] = atrousLumStopRecip(sigmaL, sum);
            }
            pil[0] = atrousLumStopRecip(sigmaL, f.prefilteredVariance(0, y));
            pil[w - 1] = atrousLumStopRecip(sigmaL, f.prefilteredVariance(w - 1, y));
        } else {
            for (int x = 0; x < w; ++x)
                pil[x] = atrousLumStopRecip(sigmaL, f.prefilteredVariance(x, y));
        }
        for (int x = 0; x < w; ++x) aw[x] = ar[x] = ag[x] = ab[x] = av[x] = 0.0f;

        // Centre-row plane pointers; a tap reads them at x + I·step + dRow.
        const float* ATROUS_RESTRICT pr = f.illum.channel(0) + rowP;
        const float* ATROUS_RESTRICT pg = f.illum.channel(1) + rowP;
        const float* ATROUS_RESTRICT pb = f.illum.channel(2) + rowP;
        const float* ATROUS_RESTRICT pv = var + rowP;
        const float* ATROUS_RESTRICT plen = f.length.channel(0) + rowP;
        const float* ATROUS_RESTRICT pz = f.depth.channel(0) + rowP;
        const float* ATROUS_RESTRICT pnx = f.normal.channel(0) + rowP;
        const float* ATROUS_RESTRICT pny = f.normal.channel(1) + rowP;
        const float* ATROUS_RESTRICT pnz = f.normal.channel(2) + rowP;
        const float* ATROUS_RESTRICT pgx = f.depthGrad.channel(0) + rowP;
        const float* ATROUS_RESTRICT pgy = f.depthGrad.channel(1) + rowP;

        for (int j = -2; j <= 2; ++j) {
            const int yq = y + j * s;
            if (yq < 0 || yq >= h) continue;  // dropped tap row, as in the functor
            const ptrdiff_t dRow = ptrdiff_t(yq - y) * w;
            const float hy = b3Tap(j);
            const float dy = float(j * s);
            if (j != 0) {
#pragma omp simd
                for (int x = x0; x < x1; ++x) {
                    ATROUS_SVGF_CENTRE
                    ATROUS_SVGF_TAP(-2, true)
                    ATROUS_SVGF_TAP(-1, true)
                    ATROUS_SVGF_TAP(0, true)
                    ATROUS_SVGF_TAP(1, true)
                    ATROUS_SVGF_TAP(2, true)
                    ATROUS_SVGF_STORE
                }
            } else {
#pragma omp simd
                for (int x = x0; x < x1; ++x) {
                    ATROUS_SVGF_CENTRE
                    ATROUS_SVGF_TAP(-2, true)
                    ATROUS_SVGF_TAP(-1, true)
                    ATROUS_SVGF_TAP(0, false)
                    ATROUS_SVGF_TAP(1, true)
                    ATROUS_SVGF_TAP(2, true)
                    ATROUS_SVGF_STORE
                }
            }
            // Border columns (within 2·step of the left/right edge): one loop per tap over the
            // columns where that tap is inside the image, in tap order, so every pixel still sums
            // its taps in the functor's order.
#define ATROUS_SVGF_BORDER_TAP(I, GEO, XA, XB)              \
    {                                                       \
        const int lo = (XA) > -(I)*s ? (XA) : -(I)*s;       \
        const int hi = (XB) < w - (I)*s ? (XB) : w - (I)*s; \
        _Pragma("omp simd") for (int x = lo; x < hi; ++x) { \
            ATROUS_SVGF_CENTRE                              \
            ATROUS_SVGF_TAP(I, GEO)                         \
            ATROUS_SVGF_STORE                               \
        }                                                   \
    }
            for (int side = 0; side < 2; ++side) {
                const int xa = side == 0 ? 0 : x1, xb = side == 0 ? x0 : w;
                ATROUS_SVGF_BORDER_TAP(-2, true, xa, xb)
                ATROUS_SVGF_BORDER_TAP(-1, true, xa, xb)
                if (j != 0)
                    ATROUS_SVGF_BORDER_TAP(0, true, xa, xb)
                else
                    ATROUS_SVGF_BORDER_TAP(0, false, xa, xb)
                ATROUS_SVGF_BORDER_TAP(1, true, xa, xb)
                ATROUS_SVGF_BORDER_TAP(2, true, xa, xb)
            }
#undef ATROUS_SVGF_BORDER_TAP
        }

        // Normalisation, or the input where nothing with information was in reach (Σw = 0).
        const float* ATROUS_RESTRICT vin = var + rowP;
        float* ATROUS_RESTRICT outR = f.outIllum.channel(0) + rowP;
        float* ATROUS_RESTRICT outG = f.outIllum.channel(1) + rowP;
        float* ATROUS_RESTRICT outB = f.outIllum.channel(2) + rowP;
        float* ATROUS_RESTRICT outV = f.outVariance.channel(0) + rowP;
#pragma omp simd
        for (int x = 0; x < w; ++x) {
            const float sw = aw[x];
            const bool keep = !(sw <= 0.0f);
            const float inv = 1.0f / sw;  // Inf where sw = 0: that lane takes the input instead
            outR[x] = selectF(keep, ar[x] * inv, pr[x]);
            outG[x] = selectF(keep, ag[x] * inv, pg[x]);
            outB[x] = selectF(keep, ab[x] * inv, pb[x]);
            outV[x] = selectF(keep, av[x] * inv * inv, vin[x]);
        }
    }
}

#undef ATROUS_SVGF_TAP
#undef ATROUS_SVGF_CENTRE
#undef ATROUS_SVGF_STORE

void levelRowsAvx2(const Atrous& f, int y0, int y1) {
    levelRowsBody(f, y0, y1);
}

#if ATROUS_CPU_AVX512
ATROUS_TARGET_AVX512 void levelRowsAvx512(const Atrous& f, int y0, int y1) {
    levelRowsBody(f, y0, y1);
}
#endif

}  // namespace

void runSvgfAtrous(const CpuExec& exec, const Atrous& f) {
    const int w = f.illum.width, h = f.illum.height;
    if (!svgfCpuFastPath()) {
        exec.forEachPixel(w, h, f);
        return;
    }
    if (w <= 0 || h <= 0) return;
    void (*rows)(const Atrous&, int, int) = &levelRowsAvx2;
#if ATROUS_CPU_AVX512
    if (svgfCpuAvx512()) rows = &levelRowsAvx512;
#endif
    tbb::parallel_for(tbb::blocked_range<int>(0, h, 8),
                      [&](const tbb::blocked_range<int>& b) { rows(f, b.begin(), b.end()); });
}

}  // namespace atrous::svgf
