// The motion-from-depth pass as the render tests set it up (tests/accumulate_test.cpp,
// tests/cuda/device_frame_cuda_test.cu): a camera move cur -> prev with the renderer's hit
// threshold and off-screen value, over the given depth and motion buffers.
#pragma once
#include "atrous/image.h"
#include "render/accumulate.h"

namespace atrous::test {

inline MotionFromDepth motionFromDepth(const pt::Camera& cur, const pt::Camera& prev, const Image& depth,
                                       Image& motion) {
    MotionFromDepth m;
    m.p.current = cur;
    m.p.previous = prev;
    m.p.moved = 1;
    m.p.hitDepth = 0.1f * kBackgroundDepth;
    m.p.offscreen = pt::kMotionOffscreen;
    m.depth = depth.view();
    m.motion = motion.view();
    return m;
}

}  // namespace atrous::test
