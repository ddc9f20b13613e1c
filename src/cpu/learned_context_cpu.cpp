// The learned filter v4's context branch on the CPU (filters/learned_context.h): the cell inputs
// row-wise (the quantities of a pixel row in vector loops, summed per column, then per cell), the
// 2x2 pooling and the x2 upsampling through the functors, the four 3x3 convolutions and the 1x1
// layer through oneDNN (src/cpu/dnnl_conv.cpp).
#include <algorithm>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "core/parallel.h"
#include "core/isa_dispatch.h"
#include "cpu/dnnl_conv.h"
#include "filters/learned.h"

namespace atrous::filters {

namespace {

// The cell inputs of cell rows [cy0, cy1): per pixel row the 15 quantities in vector loops (the
// same learnedCellQuantities as the functor), added per column over the cell's rows, then each
// cell's columns left to right (LearnedCellPass's order: the same values).
struct CellRows {
    ImageView d, var, albedo, normal, depth;
    LearnedTensor cells;
    ATROUS_FORCE_INLINE void operator()(int cy0, int cy1) const {
        const int w = d.width, h = d.height;
        std::vector<float> buf(size_t(kLearnedCellQ) * size_t(w));
        const bool ha = albedo.valid(), hn = normal.valid(), hd = depth.valid();
        for (int cy = cy0; cy < cy1; ++cy) {
            std::fill(buf.begin(), buf.end(), 0.0f);
            float* ATROUS_RESTRICT col = buf.data();
            const int y0 = cy * kLearnedCell, y1 = std::min(h, y0 + kLearnedCell);
            for (int y = y0; y < y1; ++y) {
                const size_t o = size_t(y) * size_t(w);
                const float *r = d.channel(0) + o, *g = d.channel(1) + o, *b = d.channel(2) + o;
                const float *vr = var.channel(0) + o, *vg = var.channel(1) + o, *vb = var.channel(2) + o;
                const float* ar = ha ? albedo.channel(0) + o : r;  // not read when absent
                const float* ag = ha ? albedo.channel(1) + o : r;
                const float* ab = ha ? albedo.channel(2) + o : r;
                const float* nx = hn ? normal.channel(0) + o : r;
                const float* ny = hn ? normal.channel(1) + o : r;
                const float* nz = hn ? normal.channel(2) + o : r;
                const float* z = hd ? depth.channel(0) + o : r;
                // One vector loop per group of quantities (one loop over all 15 stayed scalar);
                // the values are learnedCellQuantities' (the functor's).
                float *ATROUS_RESTRICT c0 = col, *ATROUS_RESTRICT c1 = col + w, *ATROUS_RESTRICT c2 = col + 2 * w,
                                       *ATROUS_RESTRICT c3 = col + 3 * w, *ATROUS_RESTRICT c4 = col + 4 * w;
#pragma omp simd
                for (int x = 0; x < w; ++x) {
                    c0[x] += learnedLogColour(r[x]);
                    c1[x] += learnedLogColour(g[x]);
                    c2[x] += learnedLogColour(b[x]);
                    const float L = learnedLum(r[x], g[x], b[x]);
                    c3[x] += L;
                    c4[x] += L * L;
                }
                float *ATROUS_RESTRICT c5 = col + 5 * w, *ATROUS_RESTRICT c6 = col + 6 * w, *ATROUS_RESTRICT c7 = col + 7 * w,
                                       *ATROUS_RESTRICT c8 = col + 8 * w, *ATROUS_RESTRICT c9 = col + 9 * w;
                if (ha) {
#pragma omp simd
                    for (int x = 0; x < w; ++x) {
                        const float a0 = learnedAlbedoIn(ar[x]), a1 = learnedAlbedoIn(ag[x]), a2 = learnedAlbedoIn(ab[x]);
                        const float a = (a0 + a1 + a2) * (1.0f / 3.0f);
                        c5[x] += a0, c6[x] += a1, c7[x] += a2, c8[x] += a, c9[x] += a * a;
                    }
                } else {
                    const float a = (1.0f + 1.0f + 1.0f) * (1.0f / 3.0f);
#pragma omp simd
                    for (int x = 0; x < w; ++x) c5[x] += 1.0f, c6[x] += 1.0f, c7[x] += 1.0f, c8[x] += a, c9[x] += a * a;
                }
                float *ATROUS_RESTRICT c10 = col + 10 * w, *ATROUS_RESTRICT c11 = col + 11 * w,
                                       *ATROUS_RESTRICT c12 = col + 12 * w, *ATROUS_RESTRICT c13 = col + 13 * w,
                                       *ATROUS_RESTRICT c14 = col + 14 * w;
                if (hn) {
#pragma omp simd
                    for (int x = 0; x < w; ++x)
                        c10[x] += learnedFinite(nx[x]), c11[x] += learnedFinite(ny[x]), c12[x] += learnedFinite(nz[x]);
                }  // absent: adds 0
                if (hd) {
#pragma omp simd
                    for (int x = 0; x < w; ++x) c13[x] += learnedDepthIn(z[x]);
                }
#pragma omp simd
                for (int x = 0; x < w; ++x) c14[x] += learnedNoiseIn(vr[x], vg[x], vb[x]);
            }
            for (int cx = 0; cx < cells.width; ++cx) {
                const int x0 = cx * kLearnedCell, x1 = std::min(w, x0 + kLearnedCell);
                float s[kLearnedCellQ];
                for (int k = 0; k < kLearnedCellQ; ++k) {
                    s[k] = 0.0f;
                    for (int x = x0; x < x1; ++x) s[k] += col[size_t(k) * w + x];
                }
                learnedCellFinish(s, (x1 - x0) * (y1 - y0), cells, cx, cy);
            }
        }
    }
};

}  // namespace

constexpr const char* kWho = "learned filter";

void runLearnedContextCpu(const CpuExec& exec, const LearnedCtxNet& net, const PreparedView& P,
                          const LearnedCtxPlanes& C) {
    cpu::parallelForIsa(cpu::activeIsa(), 0, C.cells.height, 1, CellRows{P.color, P.variance, P.albedo, P.normal, P.depth, C.cells});
    learnedConvCpu(C.cells, C.c1, net.k1, net.kb1, 3, true, kWho);
    exec.forEachPixel(C.pool.width, C.pool.height, LearnedPool2{C.c1, C.pool});
    learnedConvCpu(C.pool, C.c2, net.k2, net.kb2, 3, true, kWho);
    learnedConvCpu(C.c2, C.c3, net.k3, net.kb3, 3, true, kWho);
    exec.forEachPixel(C.cat.width, C.cat.height, LearnedUp2Cat{C.c1, C.c3, C.cat});
    learnedConvCpu(C.cat, C.c4, net.k4, net.kb4, 3, true, kWho);
    learnedConvCpu(C.c4, C.z, net.kz, net.kbz, 1, false, kWho);
}

}  // namespace atrous::filters
