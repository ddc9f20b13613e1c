// Unidirectional path tracing with next-event estimation and multiple importance sampling (power
// heuristic), Russian roulette, and the denoiser features that follow delta bounces
// (docs/rendering.md, "The buffers"). The per-pixel functor is a template on the intersector, so the CPU
// backend plugs in Embree and a GPU backend its own BVH; everything here is host/device code with
// no STL, no virtuals and no exceptions.
//
// A Tracer provides:
//   bool intersect(Vec3 o, Vec3 d, float tmax, Hit& hit) const;   // nearest hit in (0, tmax)
//   bool occluded(Vec3 o, Vec3 d, float tmax) const;              // any hit in (0, tmax)
#pragma once
#include "atrous/image.h"
#include "atrous/math.h"
#include "core/rng.h"
#include "core/sampler.h"
#include "render/bsdf.h"
#include "render/camera.h"
#include "render/lights.h"
#include "render/sampling.h"
#include "render/scene_data.h"
#include "render/scene_limits.h"

namespace atrous::pt {

// Russian roulette starts after this many bounces (earlier paths carry most of the energy).
constexpr int kRouletteStartBounce = 3;

struct PathSample {
    Vec3 radiance;
    Vec3 albedo;       // feature albedo (delta throughput included)
    Vec3 normal;       // feature normal (valid when featureHit)
    Vec3 position;     // feature position (valid when featureHit)
    float depth = -1;  // primary hit depth along the camera axis, < 0 when the camera ray escaped
    int32_t mesh = -1, material = -1;
    bool featureHit = false;
    // The primary (camera-ray) hit, for motion vectors: unlike the features above it does not
    // follow delta bounces.
    Vec3 primaryPosition;
    // Emitted radiance reaching the camera along the delta chain the features follow (an
    // emitter's front face or the environment, times the chain's throughput): the emission buffer.
    Vec3 primaryEmission;
    int32_t primaryMesh = -1;
    bool primaryHit = false;
};

ATROUS_INLINE float finiteOr0(float v) { return isFiniteF(v) ? v : 0.0f; }

ATROUS_INLINE Vec3 clamp01(Vec3 v) {
    return Vec3(clampf(v.x, 0.0f, 1.0f), clampf(v.y, 0.0f, 1.0f), clampf(v.z, 0.0f, 1.0f));
}

ATROUS_INLINE Bsdf makeBsdf(const SceneView& s, const Material& m, Vec2 uv, bool entering) {
    Bsdf b;
    b.type = m.type;
    b.albedo = m.albedo;
    if (m.texture >= 0) {
        b.albedo = sampleTexture(s, m.texture, uv);
    } else if (m.checker) {
        // Clamped before the conversion: uv * scale beyond int's range is undefined behaviour
        // (scene_limits.h bounds both; the clamp keeps any uv finite here).
        const long long cx = (long long)clampf(floorf(uv.x * m.checkerScale), -1e15f, 1e15f);
        const long long cy = (long long)clampf(floorf(uv.y * m.checkerScale), -1e15f, 1e15f);
        b.albedo = ((cx + cy) & 1) ? m.albedo2 : m.albedo;
    }
    b.alpha = clampf(m.roughness, 0.002f, 1.0f);
    b.ior = m.ior;
    b.entering = entering;
    return b;
}

// The feature albedo of a non-delta surface: the Lambertian reflectance, a conductor's F0 and a
// plastic's base colour (documented stand-ins for their directional albedo).
ATROUS_INLINE Vec3 featureAlbedo(const Bsdf& b) { return clamp01(b.albedo); }

ATROUS_INLINE Vec3 toLocal(Vec3 v, Vec3 t, Vec3 b, Vec3 n) { return Vec3(dot(v, t), dot(v, b), dot(v, n)); }
ATROUS_INLINE Vec3 fromLocal(Vec3 v, Vec3 t, Vec3 b, Vec3 n) { return t * v.x + b * v.y + n * v.z; }

template <class Tracer>
ATROUS_HOST_DEVICE PathSample tracePath(const SceneView& s, const Tracer& tracer, Vec3 o, Vec3 d, Rng& rng,
                                        int maxDepth, bool lightSampling) {
    PathSample r;
    Vec3 beta(1.0f);
    Vec3 featureThroughput(1.0f);
    bool following = true;  // still looking for the first non-delta surface (features)
    bool specular = true;   // the last bounce was a delta one (or this is the camera ray)
    float prevPdf = 0.0f;   // solid-angle pdf of the BSDF sample that made this ray
    for (int bounce = 0;; ++bounce) {
        Hit hit;
        if (!tracer.intersect(o, d, kRayInfinity, hit)) {
            Vec3 le = envRadiance(s, d);
            float w = 1.0f;
            if (!specular && lightSampling && s.env.lightIndex >= 0)
                w = powerHeuristic(prevPdf, lightPmf(s, s.env.lightIndex) * envPdf(s, d));
            r.radiance += beta * le * w;
            if (following) r.primaryEmission = featureThroughput * le;  // the sky seen directly
            if (following) r.albedo = featureThroughput * clamp01(le);
            break;
        }
        SurfaceInteraction si = surfaceAt(s, hit, o, d);
        const Material& m = s.materials[si.material];
        Vec3 wo = -d;
        bool front = dot(si.ng, wo) > 0.0f;
        if (bounce == 0) {
            r.depth = dot(si.p - s.camera.position, s.camera.forward);
            r.primaryPosition = si.p;
            r.primaryMesh = si.mesh;
            r.primaryHit = true;
        }

        if (front && maxComponent(m.emission) > 0.0f) {
            float w = 1.0f;
            if (!specular && lightSampling && si.light >= 0)
                w = powerHeuristic(prevPdf, triangleLightPdf(s, si.light, si, d, hit.t));
            r.radiance += beta * m.emission * w;
        }

        // Shade with the normals facing the incoming ray (two-sided surfaces); glass keeps
        // `front` to know whether the ray enters or leaves.
        Vec3 ng = front ? si.ng : -si.ng;
        Vec3 ns = front ? si.ns : -si.ns;
        Bsdf b = makeBsdf(s, m, si.uv, front);
        bool delta = isDelta(m.type);
        // Emission follows delta bounces like the features (docs/rendering.md, "The buffers"): a light or the sun
        // seen in a mirror or through glass is emission, which the denoisers add back rather than
        // filter (docs/decisions.md, "Renderer").
        if (following && front) r.primaryEmission = featureThroughput * m.emission;
        if (following && (!delta || bounce >= maxDepth)) {
            r.albedo = featureThroughput * (delta ? clamp01(b.albedo) : featureAlbedo(b));
            r.normal = ns;
            r.position = si.p;
            r.mesh = si.mesh;
            r.material = si.material;
            r.featureHit = true;
            following = false;
        }
        if (bounce >= maxDepth) break;

        Vec3 tt, bb;
        makeBasis(ns, tt, bb);
        Vec3 woL = toLocal(wo, tt, bb, ns);
        if (woL.z <= 0.0f) break;  // shading normal disagrees with the geometry: give up the path

        // Next-event estimation (not for delta BSDFs: a light sample has zero chance to match).
        if (lightSampling && !delta && s.numLights > 0) {
            float u0 = rng.next(), u1 = rng.next(), u2 = rng.next();
            LightSample ls = sampleLight(s, si.p, u0, u1, u2);
            if (ls.valid && dot(ls.wi, ng) > 0.0f) {
                Vec3 wiL = toLocal(ls.wi, tt, bb, ns);
                Vec3 f = bsdfEval(b, woL, wiL) * fabsf(wiL.z);
                if (maxComponent(f) > 0.0f && maxComponent(ls.li) > 0.0f) {
                    Vec3 origin = offsetRayOrigin(si.p, ng, ls.wi);
                    float tmax = ls.dist < kRayInfinity ? ls.dist * (1.0f - 1e-3f) : kRayInfinity;
                    if (!tracer.occluded(origin, ls.wi, tmax)) {
                        float w = ls.delta ? 1.0f : powerHeuristic(ls.pdf, bsdfPdf(b, woL, wiL));
                        r.radiance += beta * f * ls.li * (w / ls.pdf);
                    }
                }
            }
        }

        float uLobe = rng.next(), u1 = rng.next(), u2 = rng.next();
        BsdfSample bs = bsdfSample(b, woL, uLobe, u1, u2);
        if (!bs.valid) break;
        Vec3 wi = normalize(fromLocal(bs.wi, tt, bb, ns));
        // A reflection must leave on the incoming side of the geometry, a refraction cross it;
        // shading normals can break that, which would leak light through surfaces.
        bool transmitted = bs.wi.z < 0.0f;
        if ((dot(wi, ng) < 0.0f) != transmitted) break;
        beta *= bs.weight;
        if (following) featureThroughput *= bs.weight;  // only delta bounces get here
        specular = bs.delta;
        prevPdf = bs.pdf;
        o = offsetRayOrigin(si.p, ng, wi);
        d = wi;

        if (bounce + 1 >= kRouletteStartBounce) {
            float q = minf(0.95f, maxComponent(beta));
            if (!(rng.next() < q)) break;
            beta = beta / q;
        }
        if (!isFinite(beta)) break;
    }
    return r;
}

// Per-pixel outputs of the path tracer, one ImageView (3 channels) each.
// motion and emission are optional: a target with data == nullptr is not written.
struct RenderTargets {
    ImageView color, variance, albedo, normal, position, depth, ids;
    ImageView motion, emission;
};

// Offset written for a sample whose point was behind the previous camera: far off-screen, so a
// temporal filter treats the pixel as disoccluded (finite, unlike NaN, so it never spreads).
constexpr float kMotionOffscreen = -1.0e4f;

// What the motion vectors reproject against (animation frames, src/render/animation.h).
//   motion = (image position of the point in the previous frame) - (its image position now)
// The previous position of a primary hit on mesh m is meshToPrevious[m] * p (a row-major 3x4
// affine map, identity for static objects); background samples reproject their direction only
// (camera rotation). meshToPrevious == nullptr means every object is static.
struct MotionReprojection {
    bool enabled = false;
    Camera previousCamera;
    const float* meshToPrevious = nullptr;  // 12 floats per mesh id (host memory: CPU renderer only)
    int32_t numMeshes = 0;
};

// How the sub-pixel position of each camera sample is chosen.
//   Sobol:       point `index` of the Owen-scrambled Sobol (0,2)-sequence seeded per (pixel, seed)
//                (core/sampler.h): n = 2^m samples put one point in every elementary interval
//                of the pixel, so the coverage of an edge (e.g. a directly visible light) converges
//                like ~n^-0.75 instead of n^-0.5.
//   Independent: two uniform numbers from the sample's PCG32 stream (the previous behaviour; kept
//                for comparisons and tests).
// Every other dimension (light, BSDF, roulette) stays on the PCG32 stream in both cases. The
// variance buffer is the sample variance / n, which assumes independent samples: it remains an
// honest estimate where the pixel's value does not depend on the sub-pixel position, and becomes
// conservative (reported >= actual) where it does, i.e. at edges.
enum class PixelSampler : uint8_t { Sobol, Independent };

// Renders all samples of pixel (x, y): sample i has the global index firstSample + i; its RNG
// stream is Rng(pixel, firstSample + i, seed) and its sub-pixel position the pixel sampler's point
// of that index, so the result is independent of thread count and scheduling. Renders whose
// samples are averaged together (progressive accumulation) share the seed and use consecutive
// firstSample ranges, so their union is still one stratified sequence per pixel.
template <class Tracer>
struct PathTraceKernel {
    SceneView scene;
    Tracer tracer;
    RenderTargets out;
    int width = 0, height = 0, spp = 1, maxDepth = 8;
    uint32_t seed = 1;
    uint32_t firstSample = 0;  // global index of this render's first sample (see above)
    PixelSampler pixelSampler = PixelSampler::Sobol;
    bool lightSampling = true;
    float backgroundDepth = 1e30f;
    MotionReprojection motion;

    // Screen-space motion of one camera sample at image position (sx, sy), previous - current.
    ATROUS_HOST_DEVICE Vec3 sampleMotion(const PathSample& ps, Vec3 dir, float sx, float sy) const {
        if (!motion.enabled) return Vec3(0.0f);
        Vec3 offset = dir;  // background: direction only
        if (ps.primaryHit) {
            Vec3 p = ps.primaryPosition;
            if (motion.meshToPrevious && ps.primaryMesh >= 0 && ps.primaryMesh < motion.numMeshes) {
                const float* m = motion.meshToPrevious + 12 * ps.primaryMesh;
                p = Vec3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
                         m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
            }
            offset = p - motion.previousCamera.position;
        }
        float px = 0.0f, py = 0.0f;
        if (!projectToImage(motion.previousCamera, offset, width, height, px, py))
            return Vec3(kMotionOffscreen, kMotionOffscreen, 0.0f);
        return Vec3(px - sx, py - sy, 0.0f);
    }

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        uint32_t pixel = uint32_t(y) * uint32_t(width) + uint32_t(x);
        Vec3 mean(0.0f), m2(0.0f);  // Welford running mean and sum of squared deviations
        Vec3 albedoSum(0.0f), normalSum(0.0f), positionSum(0.0f);
        float depthSum = 0.0f;
        int featureHits = 0, depthHits = 0;
        int32_t mesh = -1, material = -1;
        Vec3 motionSum(0.0f), emissionSum(0.0f);
        const Sobol02Sequence pixelSequence(pixelSamplerSeed(pixel, seed));  // = stratifiedPixelJitter
        for (int i = 0; i < spp; ++i) {
            const uint32_t index = firstSample + uint32_t(i);
            Rng rng(pixel, index, seed);
            float jx, jy;
            if (pixelSampler == PixelSampler::Sobol) {
                Vec2 u = pixelSequence.point(index);
                jx = u.x;
                jy = u.y;
            } else {
                jx = rng.next();
                jy = rng.next();
            }
            Vec3 dir = cameraRayDirection(scene.camera, float(x) + jx, float(y) + jy, width, height);
            PathSample ps = tracePath(scene, tracer, scene.camera.position, dir, rng, maxDepth, lightSampling);
            // A NaN/Inf sample (numerical accident) counts as black rather than poisoning the pixel.
            // A sample beyond kMaxSampleRadiance is clamped so its square (the variance) stays finite.
            Vec3 v = isFinite(ps.radiance) ? minv(ps.radiance, Vec3(kMaxSampleRadiance)) : Vec3(0.0f);
            Vec3 delta = v - mean;
            mean += delta / float(i + 1);
            m2 += delta * (v - mean);
            albedoSum += ps.albedo;
            if (ps.featureHit) {
                normalSum += ps.normal;
                positionSum += ps.position;
                ++featureHits;
            }
            if (ps.depth >= 0.0f) {
                depthSum += ps.depth;
                ++depthHits;
            }
            if (out.motion.data) motionSum += sampleMotion(ps, dir, float(x) + jx, float(y) + jy);
            emissionSum += ps.primaryEmission;
            if (i == 0) {  // ids are not averaged: the first sample's
                mesh = ps.mesh;
                material = ps.material;
            }
        }
        float n = float(spp);
        // Variance of the mean: sample variance / n = (E[y^2] - E[y]^2) / (n - 1); unknown at n = 1.
        Vec3 var = spp > 1 ? m2 / (n * (n - 1.0f)) : Vec3(0.0f);
        Vec3 albedo = albedoSum / n;
        Vec3 normal = featureHits > 0 ? normalize(normalSum) : Vec3(0.0f);
        Vec3 position = featureHits > 0 ? positionSum / float(featureHits) : Vec3(0.0f);
        float depth = depthHits > 0 ? depthSum / float(depthHits) : backgroundDepth;
        // The last guard of the NaN rule (docs/reliability.md): no buffer ever holds NaN or Inf.
        for (int c = 0; c < 3; ++c) {
            out.color(x, y, c) = finiteOr0(mean[c]);
            out.variance(x, y, c) = finiteOr0(maxf(0.0f, var[c]));
            out.albedo(x, y, c) = finiteOr0(albedo[c]);
            out.normal(x, y, c) = finiteOr0(normal[c]);
            out.position(x, y, c) = finiteOr0(position[c]);
            out.depth(x, y, c) = isFiniteF(depth) ? depth : backgroundDepth;
        }
        for (int c = 0; c < 3; ++c) {
            if (out.motion.data) out.motion(x, y, c) = finiteOr0(motionSum[c] / n);
            if (out.emission.data) out.emission(x, y, c) = finiteOr0(emissionSum[c] / n);
        }
        out.ids(x, y, 0) = float(mesh);
        out.ids(x, y, 1) = float(material);
        out.ids(x, y, 2) = mesh < 0 ? -1.0f : 0.0f;
    }
};

}  // namespace atrous::pt
