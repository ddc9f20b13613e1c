// BVH benchmark: build time of the GPU BVH (Embree rtcBuildBVH + flattening) and CPU traversal
// rate of the shared host/device traversal (src/render/bvh.h) against Embree's rtcIntersect1 on
// the same ~100k-triangle scene and rays. Prints JSON; every figure is the median of several runs
// after a warm-up run.
//
//   build/bench/bench_bvh [--rays N] [--runs N] [--threads N]
#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdio>
#include <atomic>
#include <cstring>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "atrous/device.h"
#include "bench_cli.h"
#include "atrous/math.h"
#include "atrous/timer.h"
#include "render/bvh.h"
#include "render/bvh_build.h"

using namespace atrous;

namespace {

struct Mesh {
    std::vector<float> positions;
    std::vector<uint32_t> indices;
    std::vector<float> spheres;
};

// A bumpy sphere (lat-long grid with a smooth displacement: ~99k triangles) on a ground quad,
// plus 64 analytic spheres around it.
Mesh makeScene() {
    Mesh m;
    const int nu = 224, nv = 224;
    for (int j = 0; j <= nv; ++j) {
        float theta = kPi * float(j) / float(nv);
        for (int i = 0; i < nu; ++i) {
            float phi = 2.0f * kPi * float(i) / float(nu);
            float r = 1.0f + 0.08f * std::sin(7.0f * phi) * std::sin(5.0f * theta) + 0.03f * std::sin(23.0f * theta);
            m.positions.insert(m.positions.end(), {r * std::sin(theta) * std::cos(phi), r * std::cos(theta),
                                                   r * std::sin(theta) * std::sin(phi)});
        }
    }
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            uint32_t a = uint32_t(j * nu + i), b = uint32_t(j * nu + (i + 1) % nu);
            uint32_t c = a + uint32_t(nu), d = b + uint32_t(nu);
            if (j > 0) m.indices.insert(m.indices.end(), {a, c, b});
            if (j < nv - 1) m.indices.insert(m.indices.end(), {b, c, d});
        }
    uint32_t base = uint32_t(m.positions.size() / 3);
    m.positions.insert(m.positions.end(), {-6, -1.2f, -6, 6, -1.2f, -6, 6, -1.2f, 6, -6, -1.2f, 6});
    m.indices.insert(m.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-3.0f, 3.0f);
    for (int s = 0; s < 64; ++s) m.spheres.insert(m.spheres.end(), {u(rng), -0.9f + 0.1f * u(rng), u(rng), 0.15f + 0.03f * u(rng)});
    return m;
}

// Coherent rays: a 4:3 pinhole camera looking at the sphere. Incoherent rays: from random points
// near the geometry in random directions (what bounces look like).
std::vector<BvhRay> makeRays(int count, bool coherent) {
    std::vector<BvhRay> rays(size_t(count > 0 ? count : 0));
    std::mt19937 rng(coherent ? 1 : 2);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    std::normal_distribution<float> g(0.0f, 1.0f);
    int w = int(std::sqrt(double(count) * 4.0 / 3.0)), h = count / (w > 0 ? w : 1);
    for (int i = 0; i < count; ++i) {
        if (coherent) {
            int x = i % w, y = (i / w) % (h > 0 ? h : 1);
            Vec3 org(0.0f, 0.5f, 4.0f);
            Vec3 dir = normalize(Vec3((float(x) / float(w) - 0.5f) * 1.0f, (0.5f - float(y) / float(h)) * 0.75f, -1.0f));
            rays[size_t(i)] = BvhRay{org, dir};
        } else {
            Vec3 org = normalize(Vec3(g(rng), g(rng), g(rng))) * (0.9f + 0.4f * u01(rng));
            rays[size_t(i)] = BvhRay{org, normalize(Vec3(g(rng), g(rng), g(rng)))};
        }
    }
    return rays;
}

class EmbreeScene {
public:
    EmbreeScene(RTCDevice device, const Mesh& m) {
        mScene = rtcNewScene(device);
        rtcSetSceneBuildQuality(mScene, RTC_BUILD_QUALITY_HIGH);
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        void* vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, m.positions.size() / 3);
        std::memcpy(vb, m.positions.data(), m.positions.size() * 4);
        void* ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, m.indices.size() / 3);
        std::memcpy(ib, m.indices.data(), m.indices.size() * 4);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(mScene, g, 0);
        rtcReleaseGeometry(g);
        RTCGeometry s = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        void* sb = rtcSetNewGeometryBuffer(s, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 16, m.spheres.size() / 4);
        std::memcpy(sb, m.spheres.data(), m.spheres.size() * 4);
        rtcCommitGeometry(s);
        rtcAttachGeometryByID(mScene, s, 1);
        rtcReleaseGeometry(s);
        rtcCommitScene(mScene);
    }
    ~EmbreeScene() { rtcReleaseScene(mScene); }
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    float intersect(const BvhRay& r) const {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRayHit rh;
        rh.ray.org_x = r.org.x, rh.ray.org_y = r.org.y, rh.ray.org_z = r.org.z;
        rh.ray.dir_x = r.dir.x, rh.ray.dir_y = r.dir.y, rh.ray.dir_z = r.dir.z;
        rh.ray.tnear = 0.0f;
        rh.ray.tfar = INFINITY;
        rh.ray.time = 0.0f;
        rh.ray.mask = 0xFFFFFFFFu;
        rh.ray.id = 0;
        rh.ray.flags = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(mScene, &ctx, &rh);
        return rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? -1.0f : rh.ray.tfar;
    }

private:
    RTCScene mScene = nullptr;
};

// Median seconds of `runs` calls of f after one warm-up call.
template <class F>
double medianSeconds(int runs, const F& f) {
    f();
    std::vector<double> s;
    for (int i = 0; i < runs; ++i) {
        Timer t;
        f();
        s.push_back(t.seconds());
    }
    return median(s);
}

// Runs trace(ray) -> t over all rays, on one thread or on all; returns the hit count (so the
// work cannot be optimised away, and both tracers can be checked to agree).
template <class F>
long traceAll(const std::vector<BvhRay>& rays, bool parallel, const F& trace) {
    std::atomic<long> hits{0};
    auto body = [&](const tbb::blocked_range<size_t>& r) {
        long h = 0;
        for (size_t i = r.begin(); i < r.end(); ++i) h += trace(rays[i]) >= 0.0f;
        hits += h;
    };
    if (parallel) tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 1024), body);
    else body(tbb::blocked_range<size_t>(0, rays.size()));
    return hits.load();
}

}  // namespace

int main(int argc, char** argv) {
    int rayCount = 400000, runs = 7, threads = 0;
    CLI::App app{"BVH build time and CPU traversal rate (ours vs Embree rtcIntersect1); prints JSON", "bench_bvh"};
    app.add_option("--rays", rayCount, "rays per traversal test")->check(CLI::Range(1, 100000000))->capture_default_str();
    app.add_option("--runs", runs, "timed runs per figure (median kept)")->check(CLI::Range(1, 100000))->capture_default_str();
    app.add_option("--threads", threads, "TBB threads (0 = all cores)")->check(CLI::Range(0, 4096))->capture_default_str();
    if (int rc = atrous::bench::parseArgs(app, argc, argv); rc >= 0) return rc;
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0) limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);

    Mesh mesh = makeScene();
    BvhBuildInput in;
    in.positions = mesh.positions.data();
    in.vertexCount = mesh.positions.size() / 3;
    in.indices = mesh.indices.data();
    in.triangleCount = mesh.indices.size() / 3;
    in.spheres = mesh.spheres.data();
    in.sphereCount = mesh.spheres.size() / 4;

    BvhData bvh;
    double buildS = medianSeconds(runs, [&] { bvh = buildBvh(in); });
    BvhView view = bvh.view();

    RTCDevice device = rtcNewDevice(nullptr);
    std::unique_ptr<EmbreeScene> embree;
    double embreeBuildS = medianSeconds(runs, [&] {
        embree.reset();
        embree = std::make_unique<EmbreeScene>(device, mesh);
    });

    nlohmann::json out;
    out["benchmark"] = "bvh";
    out["device"] = deviceName(Device::Cpu);
    out["triangles"] = in.triangleCount;
    out["spheres"] = in.sphereCount;
    out["runs"] = runs;
    out["rays"] = rayCount;
    out["bvh"] = {{"nodes", bvh.nodes.size()},
                  {"leaves", bvh.leafCount},
                  {"max_depth", bvh.maxDepth},
                  {"bytes", bvh.nodes.size() * sizeof(BvhNode) + bvh.prims.size() * sizeof(BvhPrim)},
                  {"build_ms", buildS * 1e3}};
    out["embree_scene_commit_ms"] = embreeBuildS * 1e3;

    for (bool coherent : {true, false}) {
        std::vector<BvhRay> rays = makeRays(rayCount, coherent);
        nlohmann::json r;
        for (bool parallel : {false, true}) {
            long hitsOurs = 0, hitsEmbree = 0;
            double ours = medianSeconds(runs, [&] {
                hitsOurs = traceAll(rays, parallel, [&](const BvhRay& ray) {
                    BvhHit h = intersect(view, ray, 0.0f, INFINITY);
                    return h.hit() ? h.t : -1.0f;
                });
            });
            double emb = medianSeconds(runs, [&] {
                hitsEmbree = traceAll(rays, parallel, [&](const BvhRay& ray) { return embree->intersect(ray); });
            });
            double occ = medianSeconds(runs, [&] {
                traceAll(rays, parallel, [&](const BvhRay& ray) { return occluded(view, ray, 0.0f, INFINITY) ? 1.0f : -1.0f; });
            });
            const char* key = parallel ? "all_threads" : "one_thread";
            r[key] = {{"ours_intersect_mrays_per_s", double(rays.size()) / ours * 1e-6},
                      {"ours_occluded_mrays_per_s", double(rays.size()) / occ * 1e-6},
                      {"embree_intersect1_mrays_per_s", double(rays.size()) / emb * 1e-6},
                      {"ours_over_embree", emb / ours},
                      {"hits_ours", hitsOurs},
                      {"hits_embree", hitsEmbree}};
        }
        out[coherent ? "camera_rays" : "random_rays"] = r;
    }
    embree.reset();
    rtcReleaseDevice(device);
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
}
