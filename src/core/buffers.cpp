// The buffer table (include/atrous/buffers.h) and Frame's access by buffer.
#include "atrous/buffers.h"

#include "atrous/error.h"

namespace atrous {

namespace {

constexpr BufferInfo kBuffers[kBufferCount] = {
    {Buffer::Color, "color", 3, true, "mean radiance of the pixel's samples, linear HDR"},
    {Buffer::Variance, "variance", 3, true, "variance of the colour's mean, per channel (all zero: absent)"},
    {Buffer::Albedo, "albedo", 3, true, "reflectance in [0, 1] of the first non-delta surface"},
    {Buffer::Normal, "normal", 3, false, "world-space unit shading normal; 0 for background"},
    {Buffer::Position, "position", 3, false, "world-space hit point; 0 for background"},
    {Buffer::Depth, "depth", 1, true, "distance along the camera's forward axis, channel 0; 1e30 for background"},
    {Buffer::ObjectId, "object_id", 1, true, "ids channel 0: object (mesh) id; -1 for background"},
    {Buffer::MaterialId, "material_id", 1, true, "ids channel 1: material id; -1 for background"},
    {Buffer::Emission, "emission", 3, true, "emitted radiance of the primary hit towards the camera"},
    {Buffer::Motion, "motion", 2, false, "dx, dy in pixels: previous minus current image position"},
};

}  // namespace

const BufferInfo& bufferInfo(Buffer b) { return kBuffers[int(b)]; }
const char* bufferName(Buffer b) { return bufferInfo(b).name; }
int bufferChannels(Buffer b) { return bufferInfo(b).channels; }
bool bufferTakesGrey(Buffer b) { return bufferInfo(b).takesGrey; }

namespace {

using Slot = BufferRef Frame::*;

Slot slot(Buffer b) {
    switch (b) {
        case Buffer::Color: return &Frame::color;
        case Buffer::Variance: return &Frame::variance;
        case Buffer::Albedo: return &Frame::albedo;
        case Buffer::Normal: return &Frame::normal;
        case Buffer::Position: return &Frame::position;
        case Buffer::Depth: return &Frame::depth;
        case Buffer::ObjectId: return &Frame::ids;
        case Buffer::Emission: return &Frame::emission;
        case Buffer::Motion: return &Frame::motion;
        case Buffer::MaterialId: break;
    }
    return nullptr;
}

}  // namespace

const Image* BufferRef::image() const {
    if (!mImage && mStrided.valid())
        throw InputError("a buffer given as strided memory where this filter needs an Image (only denoise() reads strided buffers)");
    return mImage;
}

BufferRef Frame::get(Buffer b) const {
    const auto s = slot(b);
    return s ? this->*s : BufferRef();
}

Frame& Frame::set(Buffer b, BufferRef img) {
    const Slot s = slot(b);
    const BufferRef given = img.isImage() ? (img->empty() ? BufferRef() : img) : img;
    if (!s) {
        if (given) throw InputError("a frame holds the material id as channel 1 of its ids, not as a buffer of its own");
        return *this;
    }
    this->*s = given;
    return *this;
}

}  // namespace atrous
