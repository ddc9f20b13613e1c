// The learned filter v4's context branch on the CPU (filters/learned_context.h): the cell inputs,
// the 2x2 pooling and the x2 upsampling through the functors, the four 3x3 convolutions and the
// 1x1 layer through oneDNN (Debian's libdnnl-dev), on the planar views as they are (nchw; the
// kernels in the weight file's HWIO order, oneDNN's hwio tag). Primitives are made per call:
// oneDNN's own primitive cache returns them for a size it has seen.
#include <dnnl.hpp>

#include <mutex>
#include <string>

#include "atrous/error.h"
#include "core/parallel.h"
#include "filters/learned.h"

namespace atrous::filters {

namespace {

dnnl::engine& cpuEngine() {
    static dnnl::engine e(dnnl::engine::kind::cpu, 0);
    return e;
}

// out = act(conv(in, k) + b), k of size ks x ks (HWIO), zero padding ks / 2.
void dnnlConv(dnnl::stream& s, const ImageView& in, const ImageView& out, const float* k, const float* b, int ks,
              bool relu) {
    using namespace dnnl;
    using dt = memory::data_type;
    using tag = memory::format_tag;
    const memory::dim ic = in.channels, oc = out.channels, h = in.height, w = in.width, pad = ks / 2;
    const memory::desc srcMd({1, ic, h, w}, dt::f32, tag::nchw), dstMd({1, oc, h, w}, dt::f32, tag::nchw);
    const memory::desc wMd({oc, ic, ks, ks}, dt::f32, tag::hwio), bMd({oc}, dt::f32, tag::x);
    const convolution_forward::desc d(prop_kind::forward_inference, algorithm::convolution_direct, srcMd,
                                      memory::desc({oc, ic, ks, ks}, dt::f32, tag::any), bMd, dstMd, {1, 1},
                                      {pad, pad}, {pad, pad});
    primitive_attr attr;
    if (relu) {
        post_ops ops;
        ops.append_eltwise(1.0f, algorithm::eltwise_relu, 0.0f, 0.0f);
        attr.set_post_ops(ops);
    }
    const convolution_forward::primitive_desc pd(d, attr, cpuEngine());
    memory wUser(wMd, cpuEngine(), const_cast<float*>(k));
    memory wPrim = wUser;
    if (pd.weights_desc() != wMd) {  // oneDNN's blocked layout for the kernel (13 K floats at most)
        wPrim = memory(pd.weights_desc(), cpuEngine());
        reorder(wUser, wPrim).execute(s, wUser, wPrim);
    }
    memory src(srcMd, cpuEngine(), in.data), dst(dstMd, cpuEngine(), out.data);
    memory bias(bMd, cpuEngine(), const_cast<float*>(b));
    convolution_forward(pd).execute(
        s, {{DNNL_ARG_SRC, src}, {DNNL_ARG_WEIGHTS, wPrim}, {DNNL_ARG_BIAS, bias}, {DNNL_ARG_DST, dst}});
}

}  // namespace

void runLearnedContextCpu(const CpuExec& exec, const LearnedCtxNet& net, const LearnedPlanes& P,
                          const LearnedCtxPlanes& C) {
    const ImageView c1 = learnedChannels(C.cat, 0, kLearnedCtx), up = learnedChannels(C.cat, kLearnedCtx, kLearnedCtx);
    runLearnedCells(exec, P.d, P.var, P.albedo, P.normal, P.depth, C);
    try {
        dnnl::stream s(cpuEngine());
        dnnlConv(s, C.cells, c1, net.k1, net.kb1, 3, true);
        s.wait();
        exec.forEachPixel(C.pool.width, C.pool.height, LearnedPool2{c1, C.pool});
        dnnlConv(s, C.pool, C.c2, net.k2, net.kb2, 3, true);
        dnnlConv(s, C.c2, C.c3, net.k3, net.kb3, 3, true);
        s.wait();
        exec.forEachPixel(up.width, up.height, LearnedUp2{C.c3, up});
        dnnlConv(s, C.cat, C.c4, net.k4, net.kb4, 3, true);
        dnnlConv(s, C.c4, C.z, net.kz, net.kbz, 1, false);
        s.wait();
    } catch (const dnnl::error& e) {
        throw RuntimeError(std::string("learned filter: oneDNN: ") + e.what());
    }
}

}  // namespace atrous::filters
