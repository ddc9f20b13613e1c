// The learned networks' convolutions on the CPU (cpu/dnnl_conv.h). oneDNN (Debian's libdnnl-dev)
// on channels-last tensors (nhwc; the kernels in the weight files' HWIO order, reordered to
// oneDNN's choice). Primitives are made per call: oneDNN's own primitive cache returns them for a
// size it has seen.
//
// Threads: Debian's oneDNN runs on OpenMP, the rest of atrous on TBB. On a 2-core machine
// OpenMP's team woken beside TBB's spinning workers cost 5-10 ms per primitive (a 16x13x3x3 weight
// reorder took 10 ms). So oneDNN runs on the calling thread alone (omp_set_num_threads(1), which
// sets that thread's team size only), and bands of rows run as TBB tasks, each a oneDNN call.
#if ATROUS_HAVE_ONEDNN
#include <dnnl.hpp>
#include <omp.h>
#endif

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "core/parallel.h"
#include "cpu/dnnl_conv.h"

namespace atrous::filters {

#if ATROUS_HAVE_ONEDNN
namespace {

dnnl::engine& cpuEngine() {
    static dnnl::engine e(dnnl::engine::kind::cpu, 0);
    return e;
}

// The convolution's output rows [y0, y1) from the input rows they read (one above and below where
// the image has them; zero padding only at the image's edges): channels-last bands are dense.
void dnnlConvRows(const LearnedTensor& in, const LearnedTensor& out, const float* k, const float* b, int ks, bool relu,
                  bool accumulate, int y0, int y1) {
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
    post_ops ops;
    if (accumulate) ops.append_sum(1.0f);
    if (relu) ops.append_eltwise(1.0f, algorithm::eltwise_relu, 0.0f, 0.0f);
    attr.set_post_ops(ops);
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

}  // namespace

// The convolution in bands of rows on TBB's threads, one band per thread and at least 32 rows a
// band (two halves on a 2-core machine; one piece below 64 rows).
void learnedConvCpu(const LearnedTensor& in, const LearnedTensor& out, const float* k, const float* b, int ks, bool relu,
                    const char* who, bool accumulate) {
    const int h = out.height, parts = std::max(1, std::min(tbb::this_task_arena::max_concurrency(), h / 32));
    try {
        tbb::parallel_for(0, parts, [&](int i) {
            dnnlConvRows(in, out, k, b, ks, relu, accumulate, h * i / parts, h * (i + 1) / parts);
        });
    } catch (const dnnl::error& e) {
        throw RuntimeError(std::string(who) + ": oneDNN: " + e.what());
    }
}
#else
// Built without oneDNN (ATROUS_ONEDNN=OFF: the GPU check's pack): the direct-convolution functor.
void learnedConvCpu(const LearnedTensor& in, const LearnedTensor& out, const float* k, const float* b, int ks, bool relu,
                    const char*, bool accumulate) {
    if (!accumulate) {
        CpuExec{}.forEachPixel(out.width, out.height, LearnedConv{in, out, k, b, ks, relu});
        return;
    }
    std::vector<float> part(size_t(out.width) * size_t(out.height) * size_t(out.channels));
    const LearnedTensor p{part.data(), out.width, out.height, out.channels};
    CpuExec{}.forEachPixel(out.width, out.height, LearnedConv{in, p, k, b, ks, false});
    for (size_t i = 0; i < part.size(); ++i) {
        const float v = out.data[i] + part[i];
        out.data[i] = relu && v < 0.0f ? 0.0f : v;
    }
}
#endif


}  // namespace atrous::filters
