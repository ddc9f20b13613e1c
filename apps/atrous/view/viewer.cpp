// `atrous view`: GLFW window + OpenGL 3.3 core + Dear ImGui over the frame pipeline
// (view_pipeline.h). The image is tonemapped on the host and uploaded with glTexSubImage2D; ImGui
// draws it as a textured quad, so the viewer needs only GL 1.1 entry points of its own (ImGui's
// OpenGL 3 backend loads the rest). With --device cuda the result instead stays on the GPU and
// reaches the texture through a CUDA-registered pixel unpack buffer (cuda_display.h); the four
// buffer-object entry points that needs are loaded through GLFW.
#include "view/viewer.h"

#include <GLFW/glfw3.h>
// After GLFW's <GL/gl.h>: the buffer-object types and enums (PFNGLGENBUFFERSPROC, ...).
#include <GL/glext.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "atrous/device.h"
#include "atrous/error.h"
#include "atrous/render.h"
#include "core/timer.h"
#include "io/image_io.h"
#include "view/cuda_display.h"
#include "view/stage_history.h"
#include "view/view_pipeline.h"

namespace atrous::view {
namespace {

constexpr float kPanelWidth = 360.0f;

enum class BufferView {
    Result,
    Noisy,
    Variance,
    Albedo,
    Normal,
    Position,
    Depth,
    MeshIds,
    MaterialIds,
    Motion,
    Detail,
    SureFractions
};
const char* const kViewNames[] = {"result (denoised)",
                                  "color (noisy input)",
                                  "variance (std dev)",
                                  "albedo",
                                  "normal",
                                  "position",
                                  "depth",
                                  "mesh ids",
                                  "material ids",
                                  "motion vectors (SVGF)",
                                  "detail d_i (per level)",
                                  "SURE fractions s_i"};
const char* const kViewFlags[] = {"result",       "color",    "variance", "albedo",
                                  "normal",       "position", "depth",    "mesh-ids",
                                  "material-ids", "motion",   "detail",   "sure-s"};
constexpr int kViewCount = int(sizeof(kViewNames) / sizeof(kViewNames[0]));
const char* const kMethodNames[] = {"none", "eaw", "sure", "svgf"};

BufferView parseBufferView(const std::string& s) {
    for (int i = 0; i < kViewCount; ++i)
        if (s == kViewFlags[i]) return BufferView(i);
    std::string all;
    for (int i = 0; i < kViewCount; ++i) all += std::string(i ? ", " : "") + kViewFlags[i];
    throw InputError("--buffer: unknown view \"" + s + "\" (expected one of " + all + ")");
}

// ---- host tonemapping into RGBA8 ----

struct SrgbLut {
    unsigned char enc[4096];  // linear [0,1] -> 8-bit sRGB
    float dec[256];           // 8-bit sRGB -> linear
    SrgbLut() {
        for (int i = 0; i < 4096; ++i) {
            const float v = float(i) / 4095.0f;
            const float s =
                v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
            enc[i] = (unsigned char)std::lround(std::clamp(s, 0.0f, 1.0f) * 255.0f);
        }
        for (int i = 0; i < 256; ++i) {
            const float s = float(i) / 255.0f;
            dec[i] = s <= 0.04045f ? s / 12.92f : std::pow((s + 0.055f) / 1.055f, 2.4f);
        }
    }
    unsigned char operator()(float v) const {
        if (!(v > 0.0f)) return 0;  // also NaN
        if (v >= 1.0f) return 255;
        return enc[int(v * 4095.0f + 0.5f)];
    }
};
const SrgbLut& lut() {
    static const SrgbLut l;
    return l;
}

// 99th percentile of f over the pixels (robust display scale), at least `floor`.
template <class F>
float percentile99(size_t n, F f, float floor) {
    std::vector<float> v;
    v.reserve(n);
    for (size_t i = 0; i < n; ++i) {
        const float x = f(i);
        if (std::isfinite(x)) v.push_back(x);
    }
    if (v.empty()) return floor;
    const size_t k = std::min(v.size() - 1, size_t(0.99 * double(v.size())));
    std::nth_element(v.begin(), v.begin() + k, v.end());
    return std::max(v[k], floor);
}

void idColor(float id, unsigned char* px) {
    if (!(id >= 0.0f)) {
        px[0] = px[1] = px[2] = 0;
        return;
    }
    uint32_t h = uint32_t(id) * 2654435761u + 0x9E3779B9u;
    h ^= h >> 15;
    h *= 0x85EBCA6Bu;
    h ^= h >> 13;
    px[0] = (unsigned char)(64 + (h & 0xBF));
    px[1] = (unsigned char)(64 + ((h >> 8) & 0xBF));
    px[2] = (unsigned char)(64 + ((h >> 16) & 0xBF));
}

// Writes columns [x0, x1) of the display image for `view`. Returns a note for the UI when the view
// has nothing to show.
std::string tonemap(const ViewPipeline& pl, BufferView view, const Image* result, float exposure,
                    int level, int x0, int x1, std::vector<unsigned char>& rgba) {
    const int w = pl.width(), h = pl.height();
    const size_t plane = size_t(w) * h;
    const SrgbLut& L = lut();
    auto px = [&](int x, int y) { return &rgba[(size_t(y) * w + x) * 4]; };
    auto fill = [&](auto f) {
        for (int y = 0; y < h; ++y)
            for (int x = x0; x < x1; ++x) {
                unsigned char* p = px(x, y);
                f(size_t(y) * w + x, p);
                p[3] = 255;
            }
    };
    auto srgb3 = [&](const Image& img, float scale) {
        const float* d = img.data();
        fill([&](size_t i, unsigned char* p) {
            for (int c = 0; c < 3; ++c) p[c] = L(d[c * plane + i] * scale);
        });
    };
    auto lin3 = [&](const Image& img, float offset, float scale) {  // linear mapping, no sRGB curve
        const float* d = img.data();
        fill([&](size_t i, unsigned char* p) {
            for (int c = 0; c < 3; ++c) {
                const float v = (d[c * plane + i] - offset) * scale;
                p[c] = std::isfinite(v)
                           ? (unsigned char)std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)
                           : 0;
            }
        });
    };
    auto blank = [&](const std::string& why) {
        fill([&](size_t, unsigned char* p) { p[0] = p[1] = p[2] = 24; });
        return why;
    };
    switch (view) {
        case BufferView::Result:
            if (!result || result->empty()) return blank("no result yet");
            srgb3(*result, exposure);
            return "";
        case BufferView::Noisy:
            srgb3(pl.color(), exposure);
            return "";
        case BufferView::Variance: {
            if (!pl.varianceValid())
                return blank("variance: unknown at 1 sample per pixel (accumulate more frames)");
            const float* v = pl.variance().data();
            const float s = percentile99(
                plane,
                [&](size_t i) {
                    return std::sqrt(std::max(0.0f, v[i] + v[plane + i] + v[2 * plane + i]));
                },
                1e-12f);
            fill([&](size_t i, unsigned char* p) {
                for (int c = 0; c < 3; ++c)
                    p[c] = L(std::sqrt(std::max(0.0f, v[c * plane + i])) / s);
            });
            return "";
        }
        case BufferView::Albedo:
            srgb3(pl.albedo(), 1.0f);
            return "";
        case BufferView::Normal:
            lin3(pl.normal(), -1.0f, 0.5f);
            return "";
        case BufferView::Position: {
            const float* d = pl.position().data();
            const float* n = pl.normal().data();
            float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
            for (size_t i = 0; i < plane; ++i)
                if (n[i] != 0 || n[plane + i] != 0 || n[2 * plane + i] != 0)
                    for (int c = 0; c < 3; ++c) {
                        lo[c] = std::min(lo[c], d[c * plane + i]);
                        hi[c] = std::max(hi[c], d[c * plane + i]);
                    }
            fill([&](size_t i, unsigned char* p) {
                for (int c = 0; c < 3; ++c) {
                    const float r =
                        hi[c] > lo[c] ? (d[c * plane + i] - lo[c]) / (hi[c] - lo[c]) : 0.0f;
                    p[c] = (unsigned char)std::lround(std::clamp(r, 0.0f, 1.0f) * 255.0f);
                }
            });
            return "";
        }
        case BufferView::Depth: {
            const float* d = pl.depth().data();
            float lo = 1e30f, hi = 0.0f;
            for (size_t i = 0; i < plane; ++i)
                if (d[i] < 0.1f * kBackgroundDepth) {
                    lo = std::min(lo, d[i]);
                    hi = std::max(hi, d[i]);
                }
            fill([&](size_t i, unsigned char* p) {
                const bool bg = !(d[i] < 0.1f * kBackgroundDepth);
                const float r =
                    bg ? 0.0f : (hi > lo ? 1.0f - 0.85f * (d[i] - lo) / (hi - lo) : 1.0f);
                p[0] = p[1] = p[2] = (unsigned char)std::lround(r * 255.0f);
            });
            return "";
        }
        case BufferView::MeshIds:
        case BufferView::MaterialIds: {
            const float* d = pl.ids().data() + (view == BufferView::MaterialIds ? plane : 0);
            fill([&](size_t i, unsigned char* p) { idColor(d[i], p); });
            return "";
        }
        case BufferView::Motion: {
            const float* m = pl.motion().data();
            // No previous position: NaN, or the renderer's kMotionOffscreen (-1e4 pixels).
            auto none = [&](size_t i) {
                return !(std::fabs(m[i]) < 1e3f) || !(std::fabs(m[plane + i]) < 1e3f);
            };
            const float s = percentile99(
                plane,
                [&](size_t i) {
                    return none(i) ? 0.0f : std::max(std::fabs(m[i]), std::fabs(m[plane + i]));
                },
                0.5f);
            fill([&](size_t i, unsigned char* p) {
                if (none(i)) {
                    p[0] = 255, p[1] = 0, p[2] = 255;  // no history
                    return;
                }
                p[0] = (unsigned char)std::lround(std::clamp(0.5f + 0.5f * m[i] / s, 0.0f, 1.0f) *
                                                  255.0f);
                p[1] = (unsigned char)std::lround(
                    std::clamp(0.5f + 0.5f * m[plane + i] / s, 0.0f, 1.0f) * 255.0f);
                p[2] = 128;
            });
            return "";
        }
        case BufferView::Detail: {
            if (pl.detail().empty())
                return blank("detail: choose a level below the EAW level count");
            const float* d = pl.detail().data();
            const float s = percentile99(
                plane,
                [&](size_t i) {
                    return std::fabs(d[i]) + std::fabs(d[plane + i]) + std::fabs(d[2 * plane + i]);
                },
                1e-12f);
            fill([&](size_t i, unsigned char* p) {  // signed: mid grey = 0
                for (int c = 0; c < 3; ++c)
                    p[c] = (unsigned char)std::lround(
                        std::clamp(0.5f + 0.5f * d[c * plane + i] / s, 0.0f, 1.0f) * 255.0f);
            });
            return "";
        }
        case BufferView::SureFractions: {
            const Image& s = pl.sureFractions();
            if (s.empty() || level >= s.channels())
                return blank("SURE fractions: pick SURE as a method (CPU only)");
            const float* d = s.data() + size_t(level) * plane;
            fill([&](size_t i, unsigned char* p) {
                p[0] = p[1] = p[2] =
                    (unsigned char)std::lround(std::clamp(d[i], 0.0f, 1.0f) * 255.0f);
            });
            return "";
        }
    }
    return "";
}

// ---- window framebuffer -> PNG ----

void saveFramebuffer(const std::string& path, int fbw, int fbh) {
    std::vector<unsigned char> px(size_t(fbw) * fbh * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_BACK);
    glReadPixels(0, 0, fbw, fbh, GL_RGBA, GL_UNSIGNED_BYTE, px.data());
    // writePng encodes linear -> sRGB; decode the 8-bit sRGB values first (the round trip is exact
    // at 8 bits) so the saved file is the framebuffer.
    Image img(fbw, fbh, 3);
    const SrgbLut& L = lut();
    for (int y = 0; y < fbh; ++y)
        for (int x = 0; x < fbw; ++x) {
            const unsigned char* p =
                &px[(size_t(fbh - 1 - y) * fbw + x) * 4];  // GL rows are bottom-up
            for (int c = 0; c < 3; ++c) img(x, y, c) = L.dec[p[c]];
        }
    io::writePng(path, img, 1.0f);
}

std::string glfwErrorText;
void glfwErrorCallback(int code, const char* description) {
    glfwErrorText = std::string(description ? description : "unknown") + " (GLFW error " +
                    std::to_string(code) + ")";
}

// The GL 1.5 buffer-object entry points of the interop path (not exported by every libGL).
struct GlBufferFunctions {
    PFNGLGENBUFFERSPROC genBuffers = nullptr;
    PFNGLDELETEBUFFERSPROC deleteBuffers = nullptr;
    PFNGLBINDBUFFERPROC bindBuffer = nullptr;
    PFNGLBUFFERDATAPROC bufferData = nullptr;
    bool load() {
        genBuffers = reinterpret_cast<PFNGLGENBUFFERSPROC>(glfwGetProcAddress("glGenBuffers"));
        deleteBuffers = reinterpret_cast<PFNGLDELETEBUFFERSPROC>(glfwGetProcAddress("glDeleteBuffers"));
        bindBuffer = reinterpret_cast<PFNGLBINDBUFFERPROC>(glfwGetProcAddress("glBindBuffer"));
        bufferData = reinterpret_cast<PFNGLBUFFERDATAPROC>(glfwGetProcAddress("glBufferData"));
        return genBuffers && deleteBuffers && bindBuffer && bufferData;
    }
};

struct GlfwSession {
    GLFWwindow* window = nullptr;
    bool imgui = false;
    GLuint texture = 0;
    GlBufferFunctions gl;
    GLuint pbo = 0;                          // pixel unpack buffer of the CUDA interop path
    std::unique_ptr<CudaGlDisplay> interop;  // null: host upload
    ~GlfwSession() {
        interop.reset();  // unregister while the context and the buffer still exist
        if (pbo) gl.deleteBuffers(1, &pbo);
        if (texture) glDeleteTextures(1, &texture);
        if (imgui) {
            ImGui_ImplOpenGL3_Shutdown();
            ImGui_ImplGlfw_Shutdown();
            ImGui::DestroyContext();
        }
        if (window) glfwDestroyWindow(window);
        glfwTerminate();
    }
};

struct Json {
    std::ostringstream s;
    bool first = true;
    void key(const char* k) {
        s << (first ? "" : ", ") << '"' << k << "\": ";
        first = false;
    }
    void num(const char* k, double v) {
        key(k);
        s << v;
    }
    void str(const char* k, const std::string& v) {
        key(k);
        s << '"' << v << '"';
    }
};

// One frame's stages for the timing table, in pipeline order: render, accumulate, motion, then
// each computed slot's filter stages ("A sanitize", ..., "A other"), debug views, display.
std::vector<StageTime> frameStages(const ViewPipeline& pl, bool split, double displayMs) {
    const StageTimes& t = pl.times();
    std::vector<StageTime> v = {{"render", t.render}, {"accumulate", t.accumulate}, {"motion", t.motion}};
    for (int i = 0; i < (split ? 2 : 1); ++i) {
        const SlotResult& r = pl.slot(i);
        const std::string prefix = i ? "B " : "A ";
        const double slotMs = i ? t.denoiseB : t.denoiseA;
        double inStages = 0;
        for (const StageTime& s : r.stages) {
            v.push_back({prefix + s.name, s.milliseconds});
            inStages += s.milliseconds;
        }
        // Validation, noise estimation, allocations, transfers, the host copy of the result.
        v.push_back({prefix + (r.stages.empty() ? methodName(r.method) : "other"), std::max(0.0, slotMs - inStages)});
    }
    v.push_back({"debug views", t.debug});
    v.push_back({"display", displayMs});
    return v;
}

// The panel's timing table: stage, mean ms, and a bar of its share of the frame.
void stageTable(const StageHistory& h) {
    double total = 0;
    for (size_t i = 0; i < h.size(); ++i) total += h.mean(i);
    if (!ImGui::BeginTable("stages", 3, ImGuiTableFlags_SizingFixedFit | ImGuiTableFlags_RowBg)) return;
    ImGui::TableSetupColumn("stage", ImGuiTableColumnFlags_WidthFixed, 120.0f);
    ImGui::TableSetupColumn("ms", ImGuiTableColumnFlags_WidthFixed, 52.0f);
    ImGui::TableSetupColumn("share", ImGuiTableColumnFlags_WidthStretch);
    ImGui::TableHeadersRow();
    const float barH = ImGui::GetTextLineHeight() * 0.8f;
    for (size_t i = 0; i < h.size(); ++i) {
        const double ms = h.mean(i);
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(h.name(i).c_str());
        ImGui::TableNextColumn();
        ImGui::Text("%6.2f", ms);
        ImGui::TableNextColumn();
        ImGui::ProgressBar(total > 0 ? float(ms / total) : 0.0f, ImVec2(-1.0f, barH), "");
    }
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    ImGui::TextUnformatted("sum");
    ImGui::TableNextColumn();
    ImGui::Text("%6.2f", total);
    ImGui::EndTable();
}

bool comboMethod(const char* label, Method& m) {
    int i = int(m);
    const bool changed = ImGui::Combo(label, &i, kMethodNames, 4);
    m = Method(i);
    return changed;
}

}  // namespace

void runViewer(const ViewerOptions& opt) {
    // Everything that can be checked before a window opens is checked first.
    const Device device = parseDevice(opt.device);  // "cuda" without a GPU: InputError
    PipelineSettings ps;
    ps.methodA = parseMethod(opt.method);
    ps.split = !opt.compare.empty();
    if (ps.split) ps.methodB = parseMethod(opt.compare);
    ps.sppPerFrame = opt.spp;
    ps.maxDepth = opt.maxDepth;
    ps.accumulate = !opt.noAccumulate;
    BufferView view = parseBufferView(opt.bufferView);
    if (opt.frames < 0) throw InputError("--frames: must be 0 (interactive) or more");
    if (!opt.screenshot.empty()) {
        if (opt.frames == 0) throw InputError("--screenshot needs --frames N (headless mode)");
        if (io::extensionOf(opt.screenshot) != ".png")
            throw InputError("--screenshot: " + opt.screenshot + " must end in .png");
        const std::filesystem::path parent = std::filesystem::path(opt.screenshot).parent_path();
        io::ensureWritableDirectory(parent.empty() ? "." : parent.string());
    }
    if (!opt.dumpDir.empty()) {
        if (opt.frames == 0) throw InputError("--dump needs --frames N (headless mode)");
        io::ensureWritableDirectory(opt.dumpDir);
    }
    if (!(opt.exposure > 0.0f)) throw InputError("--exposure: must be > 0");
    {
        RenderSettings rs;
        rs.width = opt.width;
        rs.height = opt.height;
        rs.spp = opt.spp;
        rs.maxDepth = opt.maxDepth;
        validateRenderSettings(rs);  // names --width/--height/--spp/--max-depth
    }
    Scene scene = Scene::loadByNameOrFile(opt.scene);  // InputError naming the scene or file
    const bool headless = opt.frames > 0;

    // ---- window ----
    glfwSetErrorCallback(glfwErrorCallback);
    GlfwSession session;
    if (!glfwInit())
        throw InputError(
            "view: cannot open a window: " + glfwErrorText +
            ". No display? Run it under a virtual X server: xvfb-run -a atrous view ... --frames N "
            "--screenshot out.png (headless mode)");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_RESIZABLE, headless ? GLFW_FALSE : GLFW_TRUE);
    const int winW = opt.hideUi ? opt.width : opt.width + int(kPanelWidth);
    const int winH = opt.hideUi ? opt.height : std::max(opt.height, 720);
    session.window =
        glfwCreateWindow(winW, winH, ("atrous view: " + scene.name()).c_str(), nullptr, nullptr);
    if (!session.window)
        throw InputError(
            "view: cannot create an OpenGL 3.3 core context: " + glfwErrorText +
            " (try xvfb-run -a, or LIBGL_ALWAYS_SOFTWARE=1 for Mesa's software renderer)");
    GLFWwindow* win = session.window;
    glfwMakeContextCurrent(win);
    glfwSwapInterval(headless ? 0 : 1);

    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;  // no imgui.ini litter in the working directory
    ImGui::StyleColorsDark();
    if (!ImGui_ImplGlfw_InitForOpenGL(win, true) || !ImGui_ImplOpenGL3_Init("#version 330 core")) {
        ImGui::DestroyContext();
        throw InputError("view: cannot initialise Dear ImGui's OpenGL 3 backend");
    }
    session.imgui = true;

    ViewPipeline pl(scene, opt.width, opt.height, device, opt.seed);
    const int w = opt.width, h = opt.height;
    glGenTextures(1, &session.texture);
    glBindTexture(GL_TEXTURE_2D, session.texture);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    std::vector<unsigned char> rgba(size_t(w) * h * 4, 0);

    // CUDA: the display's pixel unpack buffer registered with CUDA (cuda_display.h). Any failure
    // keeps the host upload, and the panel says why.
    std::string displayPath = "host upload";
    if (device == Device::Cuda) {
        std::string why;
        if (!session.gl.load()) {
            why = "no GL buffer-object entry points";
        } else {
            session.gl.genBuffers(1, &session.pbo);
            session.gl.bindBuffer(GL_PIXEL_UNPACK_BUFFER, session.pbo);
            session.gl.bufferData(GL_PIXEL_UNPACK_BUFFER, GLsizeiptr(size_t(w) * h * 4), nullptr, GL_STREAM_DRAW);
            session.gl.bindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
            session.interop = createCudaGlDisplay(session.pbo, w, h, why);
        }
        displayPath = session.interop ? "CUDA-OpenGL interop (PBO)" : "host upload: CUDA-OpenGL interop unavailable (" + why + ")";
        std::fprintf(stderr, "atrous view: display: %s\n", displayPath.c_str());
    }

    // ---- state ----
    float exposure = opt.exposure;
    float splitPos = 0.5f;
    int level = 0;
    bool paused = false;
    bool uiVisible = !opt.hideUi;
    float moveSpeed = 0.5f;  // scene radii per second
    OrbitCamera orbit = OrbitCamera::fromCamera(
        pl.camera(), std::max(0.1f * pl.sceneRadius(),
                              dot(pl.sceneCenter() - pl.camera().position, pl.camera().forward)));
    std::string status, viewNote;
    char candidatesText[128] = "0,0.2,0.4,0.6,0.8,1";
    int snapCounter = 0;
    bool dragging[3] = {false, false, false};
    std::vector<double> frameMs, renderMs, accMs, motionMs, denAMs, denBMs, debugMs, displayMs;
    std::vector<double> frameCpu, renderCpu, accCpu, motionCpu, denACpu, denBCpu, debugCpu;
    StageHistory stageHistory(30);      // the panel's table: means over the last 30 frames
    StageHistory benchStages(1u << 20);  // the JSON line: medians over all frames but the first
    Timer frameTimer, lastFrame;
    double displayTime = 0;

    for (int frame = 0; !glfwWindowShouldClose(win); ++frame) {
        frameTimer.reset();
        const double cpuStart = processCpuMs();
        glfwPollEvents();
        const float dt = float(std::min(0.1, lastFrame.seconds()));
        lastFrame.reset();

        // ---- camera input (only where ImGui does not want the mouse/keyboard) ----
        int fbw = 0, fbh = 0;
        glfwGetFramebufferSize(win, &fbw, &fbh);
        const float areaW = uiVisible ? std::max(1.0f, float(fbw) - kPanelWidth) : float(fbw);
        const float areaH = float(fbh);
        const float scale = std::min(areaW / float(w), areaH / float(h));
        const float imgW = float(w) * scale, imgH = float(h) * scale;
        const float imgX = 0.5f * (areaW - imgW), imgY = 0.5f * (areaH - imgH);
        bool moved = false;
        if (!headless) {
            const pt::Camera cam = orbit.camera();
            for (int b = 0; b < 3; ++b) {
                if (ImGui::IsMouseClicked(b) && !io.WantCaptureMouse) dragging[b] = true;
                if (!io.MouseDown[b]) dragging[b] = false;
            }
            const ImVec2 d = io.MouseDelta;
            if (dragging[0] && (d.x != 0 || d.y != 0)) {  // left: orbit
                orbit.orbit(-d.x * 0.01f, d.y * 0.01f);
                moved = true;
            }
            if ((dragging[1] || dragging[2]) && (d.x != 0 || d.y != 0)) {  // right / middle: pan
                const float k = 2.0f * orbit.distance * orbit.tanHalfFov / std::max(1.0f, imgH);
                orbit.pan(cam, -d.x * k, d.y * k, 0.0f);
                moved = true;
            }
            if (!io.WantCaptureMouse && io.MouseWheel != 0.0f) {  // wheel: zoom
                orbit.zoom(std::pow(0.9f, io.MouseWheel));
                moved = true;
            }
            if (!io.WantCaptureKeyboard) {
                const float step = moveSpeed * pl.sceneRadius() * dt;
                float f = 0, r = 0, u = 0;
                if (glfwGetKey(win, GLFW_KEY_W) == GLFW_PRESS) f += step;
                if (glfwGetKey(win, GLFW_KEY_S) == GLFW_PRESS) f -= step;
                if (glfwGetKey(win, GLFW_KEY_D) == GLFW_PRESS) r += step;
                if (glfwGetKey(win, GLFW_KEY_A) == GLFW_PRESS) r -= step;
                if (glfwGetKey(win, GLFW_KEY_E) == GLFW_PRESS) u += step;
                if (glfwGetKey(win, GLFW_KEY_Q) == GLFW_PRESS) u -= step;
                if (f != 0 || r != 0 || u != 0) {
                    orbit.pan(cam, r, u, f);
                    moved = true;
                }
            }
        }
        if (opt.orbitDegPerFrame != 0.0f && !paused && frame > 0) {
            orbit.orbit(opt.orbitDegPerFrame * 3.14159265f / 180.0f, 0.0f);
            moved = true;
        }
        if (moved) pl.setCamera(orbit.camera());
        bool snapshot = ImGui::IsKeyPressed(GLFW_KEY_F12, false) ||
                        (!io.WantCaptureKeyboard && ImGui::IsKeyPressed(GLFW_KEY_P, false));
        if (!io.WantCaptureKeyboard && ImGui::IsKeyPressed(GLFW_KEY_TAB, false))
            uiVisible = !uiVisible;
        if (!io.WantCaptureKeyboard && ImGui::IsKeyPressed(GLFW_KEY_ESCAPE, false))
            glfwSetWindowShouldClose(win, 1);

        // ---- render, accumulate, denoise ----
        ps.detailLevel = view == BufferView::Detail ? level : -1;
        ps.sureFractions = view == BufferView::SureFractions;
        const bool lastFrame = headless && frame + 1 >= opt.frames;
        auto onRunningMean = [](Method m) { return m != Method::Svgf; };
        ps.needAccumulated = onRunningMean(ps.methodA) || (ps.split && onRunningMean(ps.methodB)) ||
                             !(view == BufferView::Result || view == BufferView::Motion) ||
                             snapshot || (lastFrame && !opt.dumpDir.empty());
        const bool doStep = !paused || moved || frame == 0;
        // CUDA: results stay on the GPU; the host path downloads them only when it shows them
        // (resultHost), the interop path never.
        ps.deviceResults = device == Device::Cuda;
        if (doStep) pl.step(ps);

        // ---- display image ----
        Timer dispTimer;
        {  // every frame: exposure and the view can change while paused
            const bool split = view == BufferView::Result && ps.split;
            const int xs = split ? std::clamp(int(std::lround(splitPos * float(w))), 0, w) : w;
            bool shown = false;
            // What the interop path can show straight from the GPU: the slots' results, or the
            // noisy colour (the running mean), which the pipeline keeps on the GPU too.
            const Image* left = nullptr;
            const Image* right = nullptr;
            if (session.interop && view == BufferView::Result && !pl.slot(0).deviceImage.empty() &&
                (!split || !pl.slot(1).deviceImage.empty())) {
                left = &pl.slot(0).deviceImage;
                right = split ? &pl.slot(1).deviceImage : nullptr;
            } else if (session.interop && view == BufferView::Noisy) {
                left = &pl.deviceBuffer(ViewPipeline::kColor);
            }
            if (left) {
                // GPU to GPU: tonemap kernel into the PBO, then PBO -> texture inside GL.
                try {
                    session.interop->write(*left, right, xs, exposure);
                    session.gl.bindBuffer(GL_PIXEL_UNPACK_BUFFER, session.pbo);
                    glBindTexture(GL_TEXTURE_2D, session.texture);
                    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
                    session.gl.bindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
                    viewNote.clear();
                    shown = true;
                } catch (const std::exception& e) {
                    session.interop.reset();
                    displayPath = std::string("host upload: CUDA-OpenGL interop failed (") + e.what() + ")";
                    std::fprintf(stderr, "atrous view: display: %s\n", displayPath.c_str());
                }
            }
            if (!shown) {  // host path (resultHost downloads a GPU result once)
                // Only the result view reads the results (on CUDA that downloads them once).
                const bool result = view == BufferView::Result;
                viewNote = tonemap(pl, view, result ? &pl.resultHost(0) : nullptr, exposure, level, 0, xs, rgba);
                if (split) tonemap(pl, view, result ? &pl.resultHost(1) : nullptr, exposure, level, xs, w, rgba);
                glBindTexture(GL_TEXTURE_2D, session.texture);
                glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
            }
        }
        displayTime = dispTimer.ms();

        // ---- UI ----
        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        ImDrawList* bg = ImGui::GetBackgroundDrawList();
        bg->AddImage((ImTextureID)(intptr_t)session.texture, ImVec2(imgX, imgY),
                     ImVec2(imgX + imgW, imgY + imgH));
        if (view == BufferView::Result && ps.split) {
            const float xs = imgX + splitPos * imgW;
            bg->AddLine(ImVec2(xs, imgY), ImVec2(xs, imgY + imgH), IM_COL32(255, 255, 255, 200),
                        1.0f);
            if (uiVisible) {
                bg->AddText(ImVec2(imgX + 6, imgY + 4), IM_COL32(255, 255, 255, 230),
                            methodName(ps.methodA));
                bg->AddText(ImVec2(xs + 6, imgY + 4), IM_COL32(255, 255, 255, 230),
                            methodName(ps.methodB));
            }
        }
        bool resetCamera = false;
        if (uiVisible) {
            ImGui::SetNextWindowPos(ImVec2(float(fbw) - kPanelWidth, 0), ImGuiCond_Always);
            ImGui::SetNextWindowSize(ImVec2(kPanelWidth, float(fbh)), ImGuiCond_Always);
            ImGui::Begin(
                "atrous view", nullptr,
                ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
            ImGui::PushItemWidth(150.0f);  // leaves the labels their room
            const StageTimes& t = pl.times();
            const double lastMs = frameMs.empty() ? 0.0 : frameMs.back();
            ImGui::Text("%s  %dx%d  %s", scene.name().c_str(), w, h, deviceToString(device));
            ImGui::Text("frame %d   %d spp   %.1f ms (%.1f fps)", frame + 1, pl.samplesPerPixel(),
                        lastMs, lastMs > 0 ? 1000.0 / lastMs : 0.0);
            ImGui::Text("render %.1f  accum %.1f  motion %.1f ms", t.render, t.accumulate,
                        t.motion);
            ImGui::Text("filter A %.1f (%s %.1f)  B %.1f ms", t.denoiseA,
                        methodName(pl.slot(0).method), pl.slot(0).filterMs, t.denoiseB);
            ImGui::Text("debug views %.1f  display %.1f ms", t.debug, displayTime);
            ImGui::TextWrapped("display: %s", displayPath.c_str());
            if (ImGui::CollapsingHeader("Timing (ms, mean of last 30 frames)", ImGuiTreeNodeFlags_DefaultOpen))
                stageTable(stageHistory);
            ImGui::Separator();
            if (ImGui::SliderInt("spp / frame", &ps.sppPerFrame, 1, 64)) pl.resetAccumulation();
            if (ImGui::SliderInt("max depth", &ps.maxDepth, 0, 32)) pl.resetAccumulation();
            if (ImGui::Checkbox("accumulate", &ps.accumulate)) pl.resetAccumulation();
            ImGui::SameLine();
            ImGui::Checkbox("pause", &paused);
            ImGui::SameLine();
            if (ImGui::Button("restart")) pl.resetAccumulation();
            ImGui::SliderFloat("exposure", &exposure, 0.05f, 16.0f, "%.2f",
                               ImGuiSliderFlags_Logarithmic);
            ImGui::SliderFloat("move speed", &moveSpeed, 0.05f, 4.0f, "%.2f",
                               ImGuiSliderFlags_Logarithmic);
            if (ImGui::Button("reset camera")) resetCamera = true;
            ImGui::TextDisabled(
                "drag: left orbit, right/middle pan\nwheel zoom, WASD move, Q/E down/up");
            ImGui::Separator();
            comboMethod("method A", ps.methodA);
            ImGui::Checkbox("split screen", &ps.split);
            if (ps.split) {
                comboMethod("method B", ps.methodB);
                ImGui::SliderFloat("split", &splitPos, 0.0f, 1.0f);
            }
            int v = int(view);
            ImGui::Combo("buffer", &v, kViewNames, kViewCount);
            view = BufferView(v);
            if (view == BufferView::Detail || view == BufferView::SureFractions)
                ImGui::SliderInt("level i", &level, 0, std::max(0, ps.eaw.levels - 1));
            if (!viewNote.empty()) ImGui::TextWrapped("%s", viewNote.c_str());
            for (int i = 0; i < 2; ++i)
                if (!pl.slot(i).error.empty())
                    ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s: %s", i ? "B" : "A",
                                       pl.slot(i).error.c_str());
            if (ImGui::CollapsingHeader("EAW (also SURE's cascade)",
                                        ImGuiTreeNodeFlags_DefaultOpen)) {
                EawParams& e = ps.eaw;
                ImGui::SliderInt("levels", &e.levels, 1, 10);
                ImGui::DragFloat("sigma color (0=auto)", &e.sigmaColor, 0.01f, 0.0f, 100.0f);
                ImGui::DragFloat("color scale k_c", &e.colorScale, 0.02f, 0.01f, 20.0f);
                ImGui::SliderFloat("color level factor", &e.colorLevelFactor, 0.05f, 1.0f);
                ImGui::DragFloat("sigma normal (0=off)", &e.sigmaNormal, 0.01f, 0.0f, 10.0f);
                ImGui::Checkbox("normal / step^2", &e.normalStepScale);
                ImGui::DragFloat("sigma position (0=auto)", &e.sigmaPosition, 0.01f, 0.0f, 100.0f);
                ImGui::DragFloat("position scale k_x", &e.positionScale, 0.02f, 0.01f, 20.0f);
                ImGui::DragFloat("sigma depth (0=off)", &e.sigmaDepth, 0.005f, 0.0f, 10.0f);
                ImGui::Checkbox("id edge stop", &e.useIds);
            }
            if (ImGui::CollapsingHeader("SURE")) {
                int mode = int(ps.sure.mode);
                const char* modes[] = {"discrete", "james-stein"};
                ImGui::Combo("mode", &mode, modes, 2);
                ps.sure.mode = SureMode(mode);
                if (ImGui::InputText("candidates", candidatesText, sizeof(candidatesText))) {
                    std::vector<float> c;
                    std::stringstream ss(candidatesText);
                    std::string item;
                    bool ok = true;
                    while (std::getline(ss, item, ',')) {
                        try {
                            c.push_back(std::stof(item));
                        } catch (...) {
                            ok = false;
                        }
                    }
                    if (ok && !c.empty())
                        ps.sure.candidates = c;  // range errors surface as the slot's error
                }
                ImGui::SliderInt("window radius", &ps.sure.windowRadius, 1, 10);
                ImGui::Checkbox("correlated variance", &ps.sure.correlatedVariance);
            }
            if (ImGui::CollapsingHeader("Firefly / demodulation")) {
                ImGui::Checkbox("firefly suppression", &ps.firefly.enabled);
                ImGui::DragFloat("firefly k", &ps.firefly.k, 0.05f, 0.1f, 50.0f);
                ImGui::Checkbox("demodulate albedo", &ps.demodulate);
                ImGui::DragFloat("albedo epsilon", &ps.albedoEpsilon, 1e-4f, 1e-6f, 1.0f, "%.5f");
            }
            if (ImGui::CollapsingHeader("SVGF")) {
                SvgfParams& p = ps.svgf;
                ImGui::DragFloat("sigma_l", &p.sigmaL, 0.05f, 0.0f, 100.0f);
                ImGui::DragFloat("sigma_n", &p.sigmaN, 1.0f, 0.0f, 1024.0f);
                ImGui::DragFloat("sigma_z", &p.sigmaZ, 0.02f, 0.0f, 100.0f);
                ImGui::SliderFloat("alpha", &p.alpha, 0.01f, 1.0f);
                ImGui::SliderFloat("moments alpha", &p.momentsAlpha, 0.01f, 1.0f);
                ImGui::SliderInt("history cap", &p.historyCap, 1, 256);
                ImGui::SliderInt("svgf levels", &p.levels, 0, 10);
                ImGui::SliderInt("feedback tap", &p.feedbackTap, -1, std::max(-1, p.levels - 1));
                ImGui::SliderInt("spatial variance frames", &p.spatialVarianceFrames, 1, 32);
                ImGui::DragFloat("reproject depth tol", &p.reprojectDepthTolerance, 0.05f, 0.0f,
                                 100.0f);
                ImGui::SliderFloat("reproject normal cos", &p.reprojectNormalCos, -1.0f, 1.0f);
                ImGui::Checkbox("TAA", &p.taa);
                ImGui::SliderFloat("TAA alpha", &p.taaAlpha, 0.01f, 1.0f);
                ImGui::Checkbox("motion vectors on camera move", &ps.svgfMotionVectors);
                ImGui::TextDisabled(ps.svgfMotionVectors ? "(history reprojected)"
                                                         : "(history reset on move)");
            }
            ImGui::Separator();
            if (ImGui::Button("save snapshot (F12 / P)")) snapshot = true;
            ImGui::TextDisabled("to %s/snap_NNNN/", opt.outDir.c_str());
            if (!status.empty()) ImGui::TextWrapped("%s", status.c_str());
            ImGui::TextDisabled("Tab hides this panel, Esc quits");
            ImGui::PopItemWidth();
            ImGui::End();
        }
        if (resetCamera) {
            orbit = OrbitCamera::fromCamera(
                pl.sceneCamera(),
                std::max(0.1f * pl.sceneRadius(), dot(pl.sceneCenter() - pl.sceneCamera().position,
                                                      pl.sceneCamera().forward)));
            pl.setCamera(pl.sceneCamera());
        }
        ImGui::Render();
        glViewport(0, 0, fbw, fbh);
        glClearColor(0.08f, 0.08f, 0.09f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

        const bool last = headless && frame + 1 >= opt.frames;
        if (snapshot) {
            try {
                char name[32];
                std::snprintf(name, sizeof(name), "snap_%04d", ++snapCounter);
                const std::string dir = (std::filesystem::path(opt.outDir) / name).string();
                std::vector<std::string> files = pl.saveBuffers(dir);
                saveFramebuffer((std::filesystem::path(dir) / "screenshot.png").string(), fbw, fbh);
                status = "saved " + dir + " (" + std::to_string(files.size() + 1) + " files)";
            } catch (const std::exception& e) {
                status = std::string("snapshot failed: ") + e.what();
            }
            std::fprintf(stderr, "atrous view: %s\n", status.c_str());
        }
        if (last) {
            if (!opt.screenshot.empty()) saveFramebuffer(opt.screenshot, fbw, fbh);
            if (!opt.dumpDir.empty()) pl.saveBuffers(opt.dumpDir);
        }
        glfwSwapBuffers(win);

        frameMs.push_back(frameTimer.ms());
        frameCpu.push_back(processCpuMs() - cpuStart);
        renderCpu.push_back(pl.times().renderCpu);
        accCpu.push_back(pl.times().accumulateCpu);
        motionCpu.push_back(pl.times().motionCpu);
        denACpu.push_back(pl.times().denoiseACpu);
        denBCpu.push_back(pl.times().denoiseBCpu);
        debugCpu.push_back(pl.times().debugCpu);
        const StageTimes& t = pl.times();
        renderMs.push_back(t.render);
        accMs.push_back(t.accumulate);
        motionMs.push_back(t.motion);
        denAMs.push_back(t.denoiseA);
        denBMs.push_back(t.denoiseB);
        debugMs.push_back(t.debug);
        displayMs.push_back(displayTime);
        if (doStep) {
            const std::vector<StageTime> stages = frameStages(pl, ps.split, displayTime);
            stageHistory.add(stages);
            if (frame > 0 && (opt.benchmark || headless)) benchStages.add(stages);  // for the JSON line
        }
        if (last) break;
    }

    if (opt.benchmark || headless) {
        // The first frame (BVH already built, but first allocations, ImGui font atlas upload) is a
        // warm-up and left out when there are more.
        const size_t skip = frameMs.size() > 1 ? 1 : 0;
        auto tail = [&](const std::vector<double>& v) {
            return std::vector<double>(v.begin() + skip, v.end());
        };
        const std::vector<double> f = tail(frameMs);
        double mean = 0;
        for (double x : f) mean += x;
        mean = f.empty() ? 0 : mean / double(f.size());
        const double med = median(f);
        Json j;
        j.str("benchmark", "view");
        j.str("scene", scene.name());
        j.num("width", w);
        j.num("height", h);
        j.str("method", methodName(ps.methodA));
        j.str("compare", ps.split ? methodName(ps.methodB) : "");
        j.num("spp_per_frame", ps.sppPerFrame);
        j.num("accumulate", ps.accumulate ? 1 : 0);
        j.num("frames", double(f.size()));
        j.num("warmup_frames", double(skip));
        j.num("frame_ms_mean", mean);
        j.num("frame_ms_median", med);
        j.num("fps", med > 0 ? 1000.0 / med : 0.0);
        j.num("render_ms", median(tail(renderMs)));
        j.num("accumulate_ms", median(tail(accMs)));
        j.num("motion_ms", median(tail(motionMs)));
        j.num("denoise_a_ms", median(tail(denAMs)));
        j.num("denoise_b_ms", median(tail(denBMs)));
        j.num("debug_ms", median(tail(debugMs)));
        j.num("display_ms", median(tail(displayMs)));
        // CPU time (user + system, all threads) per frame: on a shared machine the wall-clock
        // figures above depend on the other tenants; frame CPU time / cores bounds the frame time
        // on an idle machine from below (exact when every stage keeps all cores busy).
        j.num("cpu_ms_per_frame_median", median(tail(frameCpu)));
        j.num("render_cpu_ms", median(tail(renderCpu)));
        j.num("accumulate_cpu_ms", median(tail(accCpu)));
        j.num("motion_cpu_ms", median(tail(motionCpu)));
        j.num("denoise_a_cpu_ms", median(tail(denACpu)));
        j.num("denoise_b_cpu_ms", median(tail(denBCpu)));
        j.num("debug_cpu_ms", median(tail(debugCpu)));
        const int cores = int(std::thread::hardware_concurrency());
        j.num("hardware_threads", cores);
        const double cpuMed = median(tail(frameCpu));
        j.num("fps_idle_estimate", cpuMed > 0 ? 1000.0 * std::max(1, cores) / cpuMed : 0.0);
        j.str("device", deviceName(device));
        j.str("display", displayPath);
        // Per-stage medians (ms): the pipeline's stages and each slot's filter stages as the
        // library reported them ("A level 0", ...; "A other" = the slot's wall time not in a stage).
        j.key("stage_ms");
        j.s << "{";
        for (size_t i = 0; i < benchStages.size(); ++i)
            j.s << (i ? ", " : "") << '"' << benchStages.name(i) << "\": " << benchStages.median(i);
        j.s << "}";
        std::printf("{%s}\n", j.s.str().c_str());
        std::fflush(stdout);
    }
}

}  // namespace atrous::view
