// SURE-based choice of the detail fractions s_i(p) (Kim, Moon, Yoon 2016; docs/denoising.md, "SURE details").
// SURE(s) summed over a window W(p) and the channels is
//     Σ_W [(1 - s)² d² + (2s - 1) v] = (1 - s)² ΣD + (2s - 1) ΣV,
// so the window pass only needs two box sums (ΣD = Σ d², ΣV = Σ v) per level: a horizontal pass
// (SureBoxH) and a vertical pass that also picks s and accumulates s·d_i (SureChoose).
#pragma once
#include "atrous/image.h"
#include "filters/filter_math.h"

namespace atrous {
struct CpuExec;
}

namespace atrous::filters {

constexpr int kMaxSureCandidates = 8;

struct SureChoiceParams {
    int radius = 3;
    int jamesStein = 0;  // 1: s = clip(1 - ΣV/ΣD, 0, 1)
    int count = 6;
    float candidates[kMaxSureCandidates] = {0.0f, 0.2f, 0.4f, 0.6f, 0.8f, 1.0f};
};

// The s that minimises (1 - s)² ΣD + (2s - 1) ΣV.
ATROUS_FORCE_INLINE ATROUS_INLINE float sureChoose(const SureChoiceParams& p, float sumD, float sumV) {
    if (p.jamesStein) {
        // sumD > 0 makes the ratio finite (sumV is finite), so the selects equal fmaxf/fminf.
        const float js = minSel(maxSel(1.0f - sumV / sumD, 0.0f), 1.0f);
        return sumD > 0.0f ? js : 0.0f;
    }
    float best = p.candidates[0];
    float bestRisk = sq(1.0f - best) * sumD + (2.0f * best - 1.0f) * sumV;
    for (int i = 1; i < p.count; ++i) {
        const float s = p.candidates[i];
        const float r = sq(1.0f - s) * sumD + (2.0f * s - 1.0f) * sumV;
        const bool better = r < bestRisk;  // selects, not a branch: the x loop vectorises
        bestRisk = better ? r : bestRisk;
        best = better ? s : best;
    }
    return best;
}

// Horizontal window sums of the two detail maps (D, V); borders clamp (replicate).
struct SureBoxH {
    int radius;
    ImageView in, out;  // 2 channels each
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float a = 0, b = 0;
        for (int dx = -radius; dx <= radius; ++dx) {
            const int xx = clampIdx(x + dx, in.width - 1);
            a += in(xx, y, 0);
            b += in(xx, y, 1);
        }
        out(x, y, 0) = a;
        out(x, y, 1) = b;
    }
};

// Vertical sums over rows y - r..y + r (clamped) of the horizontal sums (SureBoxH): ΣD and ΣV
// of p's window. Shared by SureChoose and the safety net (safety_net.h).
ATROUS_INLINE void sureWindowSums(const ImageView& boxH, int radius, int x, int y, float& sumD, float& sumV) {
    sumD = 0;
    sumV = 0;
    for (int dy = -radius; dy <= radius; ++dy) {
        const int yy = clampIdx(y + dy, boxH.height - 1);
        sumD += boxH(x, yy, 0);
        sumV += boxH(x, yy, 1);
    }
}

// Vertical window sums, the choice of s_i(p), and acc += s_i(p) · d_i(p), d_i = c_i - c_{i+1}.
struct SureChoose {
    SureChoiceParams p;
    ImageView boxH, cI, cNext, acc;
    ImageView sOut;  // optional: the chosen s_i (1 channel), for tests and debugging
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float sumD, sumV;
        sureWindowSums(boxH, p.radius, x, y, sumD, sumV);
        const float s = sureChoose(p, sumD, sumV);
        for (int c = 0; c < 3; ++c) acc(x, y, c) += s * (cI(x, y, c) - cNext(x, y, c));
        if (sOut.valid()) sOut(x, y, 0) = s;
    }
};

// Run the two window passes on `exec`; the CpuExec overloads (src/cpu/sure_cpu.cpp) run
// vectorised row loops with the same sums in the same order.
template <class Exec>
void runSureBoxH(const Exec& exec, const SureBoxH& f) {
    exec.forEachPixel(f.in.width, f.in.height, f);
}
template <class Exec>
void runSureChoose(const Exec& exec, const SureChoose& f) {
    exec.forEachPixel(f.boxH.width, f.boxH.height, f);
}
void runSureBoxH(const CpuExec& exec, const SureBoxH& f);
void runSureChoose(const CpuExec& exec, const SureChoose& f);

// Both passes of a level: box.out is choose.boxH. The CpuExec overload (src/cpu/sure_cpu.cpp) keeps
// the horizontal sums of a band of rows in a ring of 2r+1 rows instead of a 2-plane image (box.out
// and choose.boxH are not used there and may be invalid); the same sums in the same order.
template <class Exec>
void runSureWindow(const Exec& exec, const SureBoxH& box, const SureChoose& choose) {
    runSureBoxH(exec, box);
    runSureChoose(exec, choose);
}
void runSureWindow(const CpuExec& exec, const SureBoxH& box, const SureChoose& choose);

}  // namespace atrous::filters
