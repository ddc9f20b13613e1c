// The learned filter v4 on the GPU: the functors of filters/learned.h launched by CudaExec (the
// context branch's passes and direct convolutions of filters/learned_context.h, one thread per
// output sample; pass A, pass B one thread per pixel with the MLP in registers, the five levels as
// AtrousLevel<LearnedStop>).
// The weights are copied to the device and the temporaries (a device image and a buffer) made once per call,
// or once for all the calls that share a LearnedCache (SVGF's frames).
#include <chrono>

#include "atrous/error.h"
#include "cuda/cuda_exec.cuh"
#include "cuda/device_buffer.cuh"
#include "filters/learned.h"

namespace atrous::filters {

void runLearned(const CudaExec& exec, const LearnedWeights& weights, const PreparedView& in, const ImageView& out,
                LearnedStageTimes* times, LearnedCache* cache) {
    checkLearnedPlanes(weights, in, out);
    const int w = in.color.width, h = in.color.height;
    const auto t0 = std::chrono::steady_clock::now();
    // The network's device copy and the temporaries: made here, or kept in the cache.
    struct Store {
        cuda::DeviceBuffer<LearnedNet> net{1};
        Image temps;
        cuda::DeviceBuffer<float> ctx;  // the context branch's planes, one block (not an Image: it
                                        // can pass the 16384 a side an image may have)
    };
    LearnedCache local;
    LearnedCache& c = cache ? *cache : local;
    if (!c.holds(weights, w, h)) {
        c = LearnedCache{};  // the old copy goes first (device memory)
        auto store = std::make_shared<Store>();
        store->net.upload(&weights.impl->net, 1);
        store->temps = Image(w, h, kLearnedTempChannels, Device::Cuda);
        LearnedCtxPlanes ctx;
        if (weights.impl->net.context) {
            store->ctx = cuda::DeviceBuffer<float>(learnedCtxFloats(w, h));
            ctx = learnedCtxPlanes(store->ctx.data(), w, h);
        }
        c = LearnedCache{w, h, weights.impl, store, learnedTemps(store->temps.data(), w, h), store->net.data(), ctx};
    }
    runLearnedFunctors(exec, c.net, in, c.temps, out, c.ctx);
    exec.synchronize();
    if (times) times->levels = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace atrous::filters
