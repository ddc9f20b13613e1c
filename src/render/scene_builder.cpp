// SceneBuilder::finalize (scene_builder.h): the bounding sphere, the light list and its power
// distribution, the environment map's sampling distribution.
#include "render/scene_builder.h"

#include "render/lights.h"
#include "render/sampling.h"

namespace atrous::pt {

namespace {

// cdf[0..n] of n non-negative weights f with sum `sum`: the running sums over the sum (uniform
// steps when the sum is 0), cdf[0] = 0 and cdf[n] = 1 exactly. The env map's rows and marginal.
void fillCdf(float* cdf, const double* f, int n, double sum) {
    double run = 0.0;
    cdf[0] = 0.0f;
    for (int i = 0; i < n; ++i) {
        run += f[i];
        cdf[i + 1] = sum > 0.0 ? float(run / sum) : float(i + 1) / float(n);
    }
    cdf[n] = 1.0f;
}

}  // namespace

std::shared_ptr<SceneData> SceneBuilder::finalize() {
    // Bounding sphere of geometry and camera (ray offsets, environment light power).
    Vec3 lo(1e30f), hi(-1e30f);
    for (const Vec3& p : d.positions) { lo = minv(lo, p); hi = maxv(hi, p); }
    for (const Sphere& s : d.spheres) { lo = minv(lo, s.center - Vec3(s.radius)); hi = maxv(hi, s.center + Vec3(s.radius)); }
    lo = minv(lo, d.camera.position);
    hi = maxv(hi, d.camera.position);
    d.sceneRadius = maxf(1e-3f, 0.5f * length(hi - lo));

    // Lights: emissive triangles, point lights, the environment. Chosen proportionally to an
    // estimate of their power (luminance), which keeps dim lights from eating samples.
    std::vector<float> power;
    d.lights.clear();
    for (size_t t = 0; t < d.triMaterial.size(); ++t) {
        const Material& m = d.materials[d.triMaterial[t]];
        if (maxComponent(m.emission) <= 0.0f) continue;
        const uint32_t* idx = d.indices.data() + 3 * t;
        float area = 0.5f * length(cross(d.positions[idx[1]] - d.positions[idx[0]], d.positions[idx[2]] - d.positions[idx[0]]));
        if (area <= 0.0f) continue;
        Light l;
        l.type = LightType::Triangle;
        l.triangle = int32_t(t);
        d.triLight[t] = int32_t(d.lights.size());
        d.lights.push_back(l);
        power.push_back(kPi * area * maxf(1e-6f, luminance(m.emission)));
    }
    for (const Light& l : pointLights) {
        d.lights.push_back(l);
        power.push_back(4.0f * kPi * maxf(1e-6f, luminance(l.intensity)));
    }
    d.envDist.clear();
    if (d.env.type == EnvType::Map) {
        const Texture& t = d.textures[d.env.texture];
        const int w = t.width, h = t.height;
        // func(u, v) = luminance * sin(theta): the lat-long map's texel solid angle goes with
        // sin(theta), so this samples directions in proportion to radiance.
        d.env.condCdf = 0;
        d.env.condInt = int64_t(h) * (w + 1);
        d.env.margCdf = d.env.condInt + h;
        d.envDist.assign(size_t(d.env.margCdf) + h + 1, 0.0f);
        std::vector<double> rowInt(h);
        size_t plane = size_t(w) * h;
        double total = 0.0;
        for (int y = 0; y < h; ++y) {
            float sinTheta = std::sin((y + 0.5f) * kPi / h);
            float* cdf = d.envDist.data() + size_t(y) * (w + 1);
            double acc = 0.0;
            std::vector<double> f(w);
            for (int x = 0; x < w; ++x) {
                const float* p = d.texels.data() + t.offset + size_t(y) * w + x;
                f[x] = std::max(0.0, double(luminance(Vec3(p[0], p[plane], p[2 * plane])))) * sinTheta;
                acc += f[x];
            }
            fillCdf(cdf, f.data(), w, acc);
            rowInt[y] = acc / w;
            d.envDist[size_t(d.env.condInt) + y] = float(acc / w);
            total += acc / w;
        }
        float* marg = d.envDist.data() + d.env.margCdf;
        fillCdf(marg, rowInt.data(), h, total);
        d.env.margInt = float(total / h);
        // Average radiance over the sphere (sin-weighted mean of the map's luminance) for the power.
        double avg = 0.0, wsum = 0.0;
        for (int y = 0; y < h; ++y) {
            double st = std::sin((y + 0.5) * kPi / h);
            avg += rowInt[y];
            wsum += st;
        }
        float avgL = wsum > 0.0 ? float(avg / wsum) * luminance(d.env.color) : 0.0f;
        if (total > 0.0) {
            d.env.lightIndex = int32_t(d.lights.size());
            Light l;
            l.type = LightType::Environment;
            d.lights.push_back(l);
            power.push_back(kPi * d.sceneRadius * d.sceneRadius * 4.0f * kPi * maxf(1e-6f, avgL));
        }
    } else if (d.env.type == EnvType::Constant && maxComponent(d.env.color) > 0.0f) {
        d.env.lightIndex = int32_t(d.lights.size());
        Light l;
        l.type = LightType::Environment;
        d.lights.push_back(l);
        power.push_back(kPi * d.sceneRadius * d.sceneRadius * 4.0f * kPi * maxf(1e-6f, luminance(d.env.color)));
    }
    d.lightCdf.assign(d.lights.size() + 1, 0.0f);
    double sum = 0.0;
    for (float p : power) sum += p;
    double run = 0.0;
    for (size_t i = 0; i < power.size(); ++i) {
        run += power[i];
        d.lightCdf[i + 1] = float(run / sum);
    }
    if (!power.empty()) d.lightCdf.back() = 1.0f;
    return std::make_shared<SceneData>(std::move(d));
}

Material diffuse(Vec3 albedo) {
    Material m;
    m.type = MaterialType::Diffuse;
    m.albedo = albedo;
    return m;
}

Material emissive(Vec3 radiance) {
    Material m = diffuse(Vec3(0.0f));
    m.emission = radiance;
    return m;
}

}  // namespace atrous::pt
