// One frame of named buffers: the vocabulary of the renderer's output, the file readers, every
// denoiser (denoise(), SvgfDenoiser, the sequence methods) and Python. Each buffer's channels and
// conventions are stated here, once; docs/inputs.md says how other renderers' passes are mapped
// onto them.
#pragma once
#include <cstddef>
#include <cstdint>
#include <initializer_list>

#include "atrous/image.h"

namespace atrous {

// The buffers, in the order of bufferInfo's table. ObjectId and MaterialId are the two passes a
// renderer writes for ids (Blender's IndexOB and IndexMA); in a Frame they are one image, `ids`
// (channel 0 the object, channel 1 the material).
enum class Buffer { Color, Variance, Albedo, Normal, Position, Depth, ObjectId, MaterialId, Emission, Motion };
constexpr int kBufferCount = 10;

struct BufferInfo {
    Buffer buffer;
    const char* name;     // "color", ...: atrous's file NAME.exr, --pass NAME=..., Python's key
    int channels;         // the components a buffer takes: 3, but depth, object_id, material_id 1, motion 2
    bool takesGrey;       // one channel may stand for all three (colour, variance, albedo, emission)
    const char* meaning;  // the convention: units, sign, the background's value
};

// The table, one row per buffer in enum order:
//   color     mean radiance of the pixel's samples, linear HDR (W sr^-1 m^-2 per channel)
//   variance  variance of that mean per channel, (E[y^2] - E[y]^2) / (n - 1); all zero (a 1-spp
//             render) counts as absent: the noise is then estimated from the image
//   albedo    directional reflectance in [0, 1] of the first non-delta surface (delta-bounce
//             throughput multiplied in); read values are clamped to [0, 1]
//   normal    world-space unit shading normal of that surface; 0 for background
//   position  world-space point of that surface; 0 for background
//   depth     distance of the primary hit along the camera's forward axis, in channel 0 (further
//             channels are ignored; atrous's renderer repeats it in R, G, B); 1e30 for background
//             (>= 1e29 is background; read values <= 0, >= 1e9 or non-finite become 1e30)
//   object_id channel 0 of `ids`: the object (mesh) id, -1 for background
//   material_id channel 1 of `ids`: the material id, -1 for background (absent: one material)
//   emission  emitted radiance of the primary hit towards the camera, 0 elsewhere
//   motion    channel 0 = dx, channel 1 = dy in pixels: the point's image position in the previous
//             frame minus its position now (previous - current); non-finite = no history
// A set of buffers: what a method reads (its registry row), what a reader decodes.
class BufferMask {
public:
    constexpr BufferMask() = default;
    constexpr BufferMask(std::initializer_list<Buffer> buffers) {
        for (Buffer b : buffers) mBits |= bit(b);
    }
    static constexpr BufferMask all() { return BufferMask((1u << kBufferCount) - 1u); }
    constexpr bool has(Buffer b) const { return (mBits & bit(b)) != 0; }
    constexpr bool empty() const { return mBits == 0; }
    constexpr BufferMask with(Buffer b) const { return BufferMask(mBits | bit(b)); }
    constexpr BufferMask without(Buffer b) const { return BufferMask(mBits & ~bit(b)); }
    constexpr BufferMask operator|(BufferMask o) const { return BufferMask(mBits | o.mBits); }
    constexpr BufferMask operator&(BufferMask o) const { return BufferMask(mBits & o.mBits); }
    constexpr bool operator==(BufferMask o) const { return mBits == o.mBits; }
    constexpr bool operator!=(BufferMask o) const { return mBits != o.mBits; }
    constexpr uint32_t bits() const { return mBits; }

private:
    constexpr explicit BufferMask(uint32_t bits) : mBits(bits) {}
    static constexpr uint32_t bit(Buffer b) { return 1u << unsigned(b); }
    uint32_t mBits = 0;
};

const BufferInfo& bufferInfo(Buffer b);
const char* bufferName(Buffer b);  // bufferInfo(b).name
int bufferChannels(Buffer b);      // bufferInfo(b).channels
bool bufferTakesGrey(Buffer b);    // bufferInfo(b).takesGrey

// One buffer of a Frame, not owned: an Image, or an image in the caller's memory and layout
// (StridedImage: float32 or float16, interleaved or planar, byte strides), or nothing. It reads as
// the pointer it replaces (`if (f.albedo)`, `f.albedo->width()`, `const Image* a = f.albedo`), and
// code that needs an Image of a buffer given as strided memory gets an InputError saying so, never
// a null pointer: denoise() reads strided buffers where they are (the colour) or converts them
// (the features, counted in DenoiseReport::copies); other denoisers take Images.
class BufferRef {
public:
    BufferRef() = default;
    BufferRef(std::nullptr_t) {}
    BufferRef(const Image* image) : mImage(image) {}
    BufferRef(const StridedImage& strided) : mStrided(strided) {}  // data null: absent
    explicit operator bool() const { return mImage || mStrided.valid(); }
    bool operator==(std::nullptr_t) const { return !*this; }
    bool operator!=(std::nullptr_t) const { return bool(*this); }
    // The Image (null when absent); InputError for a buffer given as strided memory.
    operator const Image*() const { return image(); }
    const Image* operator->() const { return image(); }
    const Image& operator*() const { return *image(); }
    const Image* image() const;
    bool isImage() const { return mImage != nullptr; }  // given as an Image
    // Either way as a StridedImage (an Image's planar float32 layout); data null when absent.
    StridedImage strided() const { return mImage ? mImage->strided() : mStrided; }
    int width() const { return strided().width; }
    int height() const { return strided().height; }
    int channels() const { return strided().channels; }
    Device device() const { return strided().device; }

private:
    const Image* mImage = nullptr;
    StridedImage mStrided;
};

// One frame's buffers, not owned, each of the colour's size on the host or on the denoiser's
// device: an Image, or (for denoise()) strided memory in the caller's layout; absent = null. What
// every denoiser takes: a denoiser reads the buffers it uses and ignores the others (denoise() no
// motion; SVGF no variance or position; the sequence methods all of them). Non-finite values are
// treated as missing for that pixel.
struct Frame {
    // Not an aggregate: the buffers are set by name (f.color = &c; ...), never by position, so that
    // code written for an older order (SVGF's: color, albedo, normal, depth, ids, motion, emission)
    // does not compile instead of silently taking one buffer for another.
    Frame() {}
    BufferRef color;
    BufferRef variance;
    BufferRef albedo;
    BufferRef normal;
    BufferRef position;
    BufferRef depth;     // 1 channel or more
    BufferRef ids;       // object_id, and material_id in channel 1 when it has two
    BufferRef emission;
    BufferRef motion;    // 2 channels or more
    // By buffer: ObjectId is `ids`; MaterialId is no slot of its own (get gives none; set throws
    // InputError for an image, takes none). set() takes an empty image as absent.
    BufferRef get(Buffer b) const;
    Frame& set(Buffer b, BufferRef buffer);
};

}  // namespace atrous
