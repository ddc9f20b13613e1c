// The learned filter v4's context branch on the CPU (filters/learned_context.h): the cell inputs
// row-wise (the quantities of a pixel row in vector loops, summed per column, then per cell), the
// 2x2 pooling and the x2 upsampling through the functors, the four 3x3 convolutions and the 1x1
// layer through oneDNN (Debian's libdnnl-dev) on the channels-last tensors (nhwc; the kernels in
// the weight file's HWIO order, reordered to oneDNN's choice). Primitives are made per call:
// oneDNN's own primitive cache returns them for a size it has seen.
//
// Threads: Debian's oneDNN runs on OpenMP, the rest of atrous on TBB. On this 2-core machine
// OpenMP's team woken beside TBB's spinning workers cost 5-10 ms per primitive (a 16x13x3x3 weight
// reorder took 10 ms); each convolution here is a few ms on one core. So oneDNN runs on the calling
// thread alone (omp_set_num_threads(1), which sets that thread's team size only), and the
// convolutions over the image's halves run as two TBB tasks, each a oneDNN call on its rows.
#if ATROUS_HAVE_ONEDNN
#include <dnnl.hpp>
#include <omp.h>
#endif

#include <tbb/parallel_for.h>

#include <algorithm>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "core/parallel.h"
#include "core/isa_dispatch.h"
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

#if ATROUS_HAVE_ONEDNN
dnnl::engine& cpuEngine() {
    static dnnl::engine e(dnnl::engine::kind::cpu, 0);
    return e;
}

// The convolution's output rows [y0, y1) from the input rows they read (one above and below where
// the image has them; zero padding only at the image's edges): channels-last bands are dense.
void dnnlConvRows(const LearnedTensor& in, const LearnedTensor& out, const float* k, const float* b, int ks, bool relu,
                  int y0, int y1) {
    const int pad = ks / 2, i0 = std::max(0, y0 - pad), i1 = std::min(in.height, y1 + pad);
    using namespace dnnl;
    using dt = memory::data_type;
    using tag = memory::format_tag;
    const memory::dim ic = in.channels, oc = out.channels, w = in.width;
    const memory::desc srcMd({1, ic, i1 - i0, w}, dt::f32, tag::nhwc), dstMd({1, oc, y1 - y0, w}, dt::f32, tag::nhwc);
    const memory::desc wMd({oc, ic, ks, ks}, dt::f32, tag::hwio), bMd({oc}, dt::f32, tag::x);
    const memory::dim padTop = pad - (y0 - i0), padBottom = pad - (i1 - y1);
    const convolution_forward::desc d(prop_kind::forward_inference, algorithm::convolution_direct, srcMd,
                                      memory::desc({oc, ic, ks, ks}, dt::f32, tag::any), bMd, dstMd, {1, 1},
                                      {padTop, pad}, {padBottom, pad});
    primitive_attr attr;
    if (relu) {
        post_ops ops;
        ops.append_eltwise(1.0f, algorithm::eltwise_relu, 0.0f, 0.0f);
        attr.set_post_ops(ops);
    }
    omp_set_num_threads(1);
    stream s(cpuEngine());
    const convolution_forward::primitive_desc pd(d, attr, cpuEngine());
    memory wUser(wMd, cpuEngine(), const_cast<float*>(k));
    memory wPrim = wUser;
    if (pd.weights_desc() != wMd) {  // oneDNN's blocked layout for the kernel (9 K floats at most)
        wPrim = memory(pd.weights_desc(), cpuEngine());
        reorder(wUser, wPrim).execute(s, wUser, wPrim);
    }
    memory src(srcMd, cpuEngine(), in.data + size_t(i0) * size_t(w) * size_t(ic));
    memory dst(dstMd, cpuEngine(), out.data + size_t(y0) * size_t(w) * size_t(oc));
    memory bias(bMd, cpuEngine(), const_cast<float*>(b));
    convolution_forward(pd).execute(
        s, {{DNNL_ARG_SRC, src}, {DNNL_ARG_WEIGHTS, wPrim}, {DNNL_ARG_BIAS, bias}, {DNNL_ARG_DST, dst}});
    s.wait();
}

// The convolution in two halves of rows on TBB's threads (one piece below 64 rows).
void conv(const LearnedTensor& in, const LearnedTensor& out, const float* k, const float* b, int ks, bool relu) {
    const int h = out.height, parts = h >= 64 ? 2 : 1;
    tbb::parallel_for(0, parts,
                      [&](int i) { dnnlConvRows(in, out, k, b, ks, relu, h * i / parts, h * (i + 1) / parts); });
}
#else
// Built without oneDNN (ATROUS_ONEDNN=OFF: the GPU check's pack): the direct-convolution functor.
void conv(const LearnedTensor& in, const LearnedTensor& out, const float* k, const float* b, int ks, bool relu) {
    CpuExec{}.forEachPixel(out.width, out.height, LearnedConv{in, out, k, b, ks, relu});
}
#endif

}  // namespace

void runLearnedContextCpu(const CpuExec& exec, const LearnedCtxNet& net, const PreparedView& P,
                          const LearnedCtxPlanes& C) {
    cpu::parallelForIsa(cpu::activeIsa(), 0, C.cells.height, 1, CellRows{P.color, P.variance, P.albedo, P.normal, P.depth, C.cells});
    auto convolutions = [&] {
        conv(C.cells, C.c1, net.k1, net.kb1, 3, true);
        exec.forEachPixel(C.pool.width, C.pool.height, LearnedPool2{C.c1, C.pool});
        conv(C.pool, C.c2, net.k2, net.kb2, 3, true);
        conv(C.c2, C.c3, net.k3, net.kb3, 3, true);
        exec.forEachPixel(C.cat.width, C.cat.height, LearnedUp2Cat{C.c1, C.c3, C.cat});
        conv(C.cat, C.c4, net.k4, net.kb4, 3, true);
        conv(C.c4, C.z, net.kz, net.kbz, 1, false);
    };
#if ATROUS_HAVE_ONEDNN
    try {
        convolutions();
    } catch (const dnnl::error& e) {
        throw RuntimeError(std::string("learned filter: oneDNN: ") + e.what());
    }
#else
    convolutions();
#endif
}

}  // namespace atrous::filters
