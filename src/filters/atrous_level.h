// One level of the à-trous cascade, written once for every filter: a 5x5 B3 kernel at step 2^i
// whose taps are weighted by an edge-stop POLICY (docs/architecture.md, "The filter layer").
// EAW and SURE (filters/eaw.h: EawStop) and SVGF (filters/svgf_atrous.h: SvgfStop) are policies;
// a new edge-stop is a new policy of a few dozen lines (tests/toy_policy_test.cpp has one), and
// runs on every backend: AtrousLevel<Stop> is the per-pixel functor any executor launches, and
// runAtrousRows<Stop> (src/cpu/atrous_rows.h) the CPU's vectorised row engine.
//
// A policy Stop provides (all ATROUS_HOST_DEVICE, the tap and centre ATROUS_FORCE_INLINE):
//   int width(), height(), step()      the level's size and tap spacing 2^i
//   static constexpr int kSums         running sums per pixel (AtrousSums<kSums>, e.g. Σw, Σwc)
//   static constexpr bool kCentreTap   the centre tap (0, 0) gets tap<0, true>; else all <QX, false>
//   static constexpr bool kRowPartialSums  CPU engine: sum each tap row from 0, then add to the
//                                      pixel's sums (false: keep adding to them); association only
//   static constexpr bool kScalarTaps  the functor calls tapScalar (may skip loads, for the GPU)
//                                      instead of tap; the two must give the same sums
//   struct Row      pointers into the planes at the start of image row y: Row row(int y)
//   struct Centre   the centre pixel's values: Centre centre(const Row&, int x)
//   struct TapRow   per tap row constants: TapRow tapRow(int qy)
//   template <int QX, bool kCentre> void tap(const Row&, const Centre&, AtrousSums<kSums>&,
//       ptrdiff_t q, float hxy, const TapRow&)   adds tap (QX, qy) read at row pointer + q with
//                                      B3 weight hxy = h(qy) h(QX); branch-free (the CPU engine
//                                      runs it in vectorised x loops)
//   void finish(const Row&, int x, int y, const AtrousSums<kSums>&)   normalise and write
// Taps outside the image are dropped (never clamped) by the functor and the engine alike.
#pragma once
#include <cstddef>

#include "atrous/image.h"
#include "filters/atrous_math.h"

namespace atrous::filters {

template <int K>
struct AtrousSums {
    float s[K];
};

template <class Stop>
struct AtrousLevel {
    Stop stop;

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int w = stop.width(), h = stop.height(), s = stop.step();
        const typename Stop::Row R = stop.row(y);
        const typename Stop::Centre c = stop.centre(R, x);
        AtrousSums<Stop::kSums> a;
        for (int k = 0; k < Stop::kSums; ++k) a.s[k] = 0.0f;
        for (int qy = -2; qy <= 2; ++qy) {
            const int yq = y + qy * s;
            if (yq < 0 || yq >= h) continue;
            const ptrdiff_t dRow = ptrdiff_t(yq - y) * w;
            const float hy = b3(qy);
            const typename Stop::TapRow T = stop.tapRow(qy);
            tapAt<-2, false>(R, c, a, x, s, w, dRow, hy, T);
            tapAt<-1, false>(R, c, a, x, s, w, dRow, hy, T);
            if constexpr (Stop::kCentreTap) {
                if (qy == 0)
                    tapAt<0, true>(R, c, a, x, s, w, dRow, hy, T);
                else
                    tapAt<0, false>(R, c, a, x, s, w, dRow, hy, T);
            } else {
                tapAt<0, false>(R, c, a, x, s, w, dRow, hy, T);
            }
            tapAt<1, false>(R, c, a, x, s, w, dRow, hy, T);
            tapAt<2, false>(R, c, a, x, s, w, dRow, hy, T);
        }
        stop.finish(R, x, y, a);
    }

    template <int QX, bool kCentre>
    ATROUS_HOST_DEVICE void tapAt(const typename Stop::Row& R, const typename Stop::Centre& c,
                                  AtrousSums<Stop::kSums>& a, int x, int s, int w, ptrdiff_t dRow, float hy,
                                  const typename Stop::TapRow& T) const {
        const int xq = x + QX * s;
        if (xq < 0 || xq >= w) return;
        if constexpr (Stop::kScalarTaps)
            stop.template tapScalar<QX, kCentre>(R, c, a, ptrdiff_t(xq) + dRow, hy * b3(QX), T);
        else
            stop.template tap<QX, kCentre>(R, c, a, ptrdiff_t(xq) + dRow, hy * b3(QX), T);
    }
};

// One level on `exec` through the functor (the CUDA path, and the CPU reference the tests compare
// the row engine with). The CpuExec overloads of the policies' run functions use the row engine.
template <class Exec, class Stop>
void runAtrousLevelFunctor(const Exec& exec, const Stop& stop) {
    exec.forEachPixel(stop.width(), stop.height(), AtrousLevel<Stop>{stop});
}

// The same after `pre`, a per-pixel functor that writes a plane the taps read at the centre
// (EAW's 1/σ_c² factors, SVGF's luminance stop).
template <class Exec, class Pre, class Stop>
void runAtrousLevelFunctor(const Exec& exec, const Pre& pre, const Stop& stop) {
    exec.forEachPixel(stop.width(), stop.height(), pre);
    runAtrousLevelFunctor(exec, stop);
}

// The plane `given`, or where it is invalid a new w x h one on exec's device, held by `store`
// (the caller synchronises before `store` dies).
template <class Exec>
ImageView levelPlane(const Exec& exec, const ImageView& given, int w, int h, Image& store) {
    if (given.valid()) return given;
    store = Image(w, h, 1, exec.device());
    return store.view();
}

// The CPU row engine is on by default; tests switch it off to compare with the functor
// (src/cpu/atrous_rows.cpp). Its AVX-512 row loops: on where the CPU has AVX-512 (F/VL/BW/DQ);
// tests switch it off to run the AVX2 loops too (the dispatch's cpu::avx512Switch(),
// src/core/cpu_isa.h). Setting it on a CPU without AVX-512 is not allowed. One pair of switches for
// every policy.
bool& atrousCpuFastPath();
bool& atrousCpuAvx512();

}  // namespace atrous::filters
