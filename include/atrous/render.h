// Rendering API: a physically based CPU path tracer (Embree 3 intersection, TBB threads) that
// writes the noisy colour together with the per-pixel buffers the denoisers use
// (docs/rendering.md, "The buffers").
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "atrous/buffers.h"
#include "atrous/image.h"
#include "atrous/param_table.h"

namespace atrous {

namespace pt {
struct SceneData;  // flat, GPU-friendly scene arrays (src/render/scene_data.h)
}

// Each field has a row in renderParams() (below): its name, range and doc line.
struct RenderSettings {
    int width = 512;
    int height = 512;
    int spp = 16;        // samples per pixel, >= 1
    uint32_t seed = 1;   // same seed -> bit-identical output, whatever the thread count
    // Global index of the first sample. Renders averaged together (progressive accumulation) keep
    // one seed and use consecutive ranges (frame * spp), so the pixel's stratified sub-pixel
    // sequence continues across them; independent renders leave it at 0.
    uint32_t firstSample = 0;
    int maxDepth = 8;    // bounces: 0 = emitted light only, 1 = direct lighting, ...
    int threads = 0;     // worker threads, 0 = all cores
    // Next-event estimation with multiple importance sampling (power heuristic). false = BSDF
    // sampling only (for tests; delta lights such as point lights then contribute nothing).
    bool lightSampling = true;
    // Optional progress counter (the CLI's progress line): the CPU renderers add pixels x spp
    // once per finished 8x8 tile (one relaxed atomic add per tile, never per pixel or sample).
    std::atomic<uint64_t>* samplesDone = nullptr;
};

// The renderer's buffers: 3-channel planar host images of width x height, each with the meaning
// and conventions of atrous/buffers.h (depth repeated in R, G, B; ids R = mesh id, G = material
// id, B = 0). motion: animation frames only (renderFrame), the mean over the pixel's samples,
// background from the camera rotation alone; empty for render(). frame() gives them as the one
// Frame every denoiser takes.
struct RenderBuffers {
    Image color, variance, albedo, normal, position, depth, ids;
    Image motion, emission;
    // Every buffer the render has (motion too, when it made one; empty images are absent), not owned.
    Frame frame() const;
};

// RenderBuffers' images by name, in declaration order: the file NAME.exr the CLI writes, the key
// of Python's dict. Code that handles every buffer walks this list.
struct RenderBufferField {
    const char* name;
    Image RenderBuffers::*image;
};
inline constexpr RenderBufferField kRenderBufferFields[] = {
    {"color", &RenderBuffers::color},   {"variance", &RenderBuffers::variance}, {"albedo", &RenderBuffers::albedo},
    {"normal", &RenderBuffers::normal}, {"position", &RenderBuffers::position}, {"depth", &RenderBuffers::depth},
    {"ids", &RenderBuffers::ids},       {"motion", &RenderBuffers::motion},     {"emission", &RenderBuffers::emission},
};

// Camera paths of animations (docs/scenes.md, "Animation"). Time t in [0, 1] spans the sequence.
//   Static     the scene's camera at every t
//   Orbit      turns about the vertical axis through the camera's target, -10..+10 degrees
//   Dolly      moves towards the target by a quarter of the distance to it
//   Keyframes  the scene's "camera.keyframes" (JSON scenes), Catmull-Rom interpolated
//   Auto       Keyframes when the scene has keyframes, else Static
enum class CameraPath { Auto, Static, Orbit, Dolly, Keyframes };

// "auto", "static", "orbit", "dolly", "keyframes"; InputError naming --camera-path otherwise.
CameraPath parseCameraPath(const std::string& name);

// Depth written for pixels that see no surface (a finite stand-in for +inf).
constexpr float kBackgroundDepth = 1e30f;

// A scene ready to render: geometry, materials, lights and camera. Cheap to copy (shared,
// immutable data).
class Scene {
public:
    Scene() = default;
    explicit Scene(std::shared_ptr<const pt::SceneData> data) : mData(std::move(data)) {}

    // One of builtinSceneNames(); throws InputError naming the unknown scene otherwise.
    static Scene builtin(const std::string& name);
    // A JSON scene file (docs/scenes.md); OBJ and texture paths are relative to the file.
    // Throws InputError naming the file and the problem.
    static Scene load(const std::string& path);
    // JSON text; `baseDir` resolves relative paths, `sourceName` names the text in errors.
    static Scene parse(const std::string& jsonText, const std::string& baseDir,
                       const std::string& sourceName = "<scene json>");
    // A path ending in .json or naming an existing file is loaded, anything else is a built-in.
    static Scene loadByNameOrFile(const std::string& nameOrPath);

    const std::string& name() const;
    // Material id (as written into ids.G) of the material called `name`; -1 when there is none.
    int materialId(const std::string& name) const;
    // Mesh id (ids.R) of the object called `name`; -1 when there is none.
    int meshId(const std::string& name) const;

    const pt::SceneData& data() const { return *mData; }

    // Whether the scene has camera keyframes / objects with a "motion".
    bool hasCameraKeyframes() const;
    bool hasMovingObjects() const;
    // The scene posed at animation time t in [0, 1]: camera on `path`, moving objects moved.
    // Call it on the scene as loaded (InputError for a posed scene, or for Keyframes on a scene
    // without keyframes).
    Scene atTime(float t, CameraPath path) const;

private:
    std::shared_ptr<const pt::SceneData> mData;
};

const std::vector<std::string>& builtinSceneNames();

// RenderSettings' parameter table (atrous/param_table.h; all but the progress counter): CLI flag
// --<name> of `atrous render` and `atrous view`, Python's keywords.
const ParamTable<RenderSettings>& renderParams();

// Throws ParamError (atrous/error.h: an InputError naming the field, `max_depth`) for settings
// outside their ranges in renderParams(): spp <= 0, width or height <= 0 or > kMaxImageDim,
// maxDepth outside 0..1024, threads outside 0..4096.
void validateRenderSettings(const RenderSettings& settings);

// Renders `scene` on the CPU (validates the settings first). motion stays empty; emission is filled.
RenderBuffers render(const Scene& scene, const RenderSettings& settings);

// Renders `scene` on `device`: Device::Cpu is render() above (Embree); Device::Cuda the CUDA path
// tracer (the same per-pixel kernel over atrous's BVH), whose buffers come back to the host.
// InputError (a ParamError naming `device`) for CUDA without the backend or a GPU.
RenderBuffers render(const Scene& scene, const RenderSettings& settings, Device device);

// Repeated renders of one scene (benchmarks, interactive loops): on CUDA the BVH is built and the
// scene uploaded once, and the buffers stay on the GPU between calls; on the CPU each call is
// render(). Construction on CUDA throws as render(..., Device::Cuda) does.
class SceneRenderer {
public:
    SceneRenderer(const Scene& scene, Device device);
    ~SceneRenderer();
    SceneRenderer(SceneRenderer&&) noexcept;
    SceneRenderer& operator=(SceneRenderer&&) noexcept;
    Device device() const { return mDevice; }
    // Host buffers, equal to render(scene, settings, device)'s.
    RenderBuffers render(const RenderSettings& settings);
    // The render where it was made, owned by the renderer and valid until its next call: on CUDA
    // its device buffers (the kernel has finished when it returns), on the CPU a host render.
    const RenderBuffers& renderInPlace(const RenderSettings& settings);

private:
    struct Impl;
    std::unique_ptr<Impl> mImpl;
    Device mDevice;
};

// Renders frame time t of the animated `scene` (as loaded) on the CPU, with motion vectors against
// time tPrev (pass tPrev = t for a first frame: then every motion vector is 0 up to rounding).
RenderBuffers renderFrame(const Scene& scene, CameraPath path, float t, float tPrev, const RenderSettings& settings);

// Time of frame f of a sequence of `frames` frames: f / max(frames - 1, 1).
inline float frameTime(int f, int frames) { return float(f) / float(frames > 1 ? frames - 1 : 1); }

}  // namespace atrous
