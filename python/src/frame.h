// One frame's arrays as the library's images, for the sequence methods (which take Images): the
// arrays become the binding's own planar images, put into the one input assembly (Frame,
// the Frame every denoiser takes), as the CLI and the viewer do. atrous.denoise hands its arrays
// over where they are instead (bindings.cpp).
#pragma once
#include <nanobind/nanobind.h>

#include <initializer_list>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "arrays.h"
#include "atrous/error.h"
#include "atrous/interop.h"
#include "atrous/io/buffer_set.h"

namespace atrous::python {

namespace nb = nanobind;

struct Buffers {
    std::vector<std::unique_ptr<Image>> owned;
    const Image& color;
    Frame refs;
    explicit Buffers(const Image& c) : color(c) { refs.set(io::Buffer::Color, &c); }
    struct Arg {
        nb::handle obj;
        io::Buffer buffer;
        const char* what;  // the keyword
    };
    Buffers& add(std::initializer_list<Arg> args) {
        for (const Arg& a : args) add(a);
        return *this;
    }
    void add(const Arg& arg) {
        if (arg.obj.is_none()) return;
        // Motion vectors and ids of 2 or more channels keep them (dx, dy; object, material id); one
        // channel is repeated into 3, as for every other buffer.
        const bool ownCount = arg.buffer == io::Buffer::Motion || arg.buffer == io::Buffer::ObjectId;
        Arrays held;
        const StridedImage a = held.strided(arg.obj, arg.what);
        const int channels = ownCount && a.channels >= 2 ? a.channels : 3;
        owned.push_back(std::make_unique<Image>(importImage(a, channels, arg.what)));
        const Image& img = *owned.back();
        if (!img.view().sameSize(color.view()))
            throw InputError(std::string(arg.what) + ": size " + std::to_string(img.width()) + "x" +
                             std::to_string(img.height()) + " differs from the color's " + std::to_string(color.width()) +
                             "x" + std::to_string(color.height()));
        if (img.device() != color.device())
            throw InputError(std::string(arg.what) + ": lives on a different device than color");
        refs.set(arg.buffer, &img);
    }
};

// A frame of a sequence with its own colour: the owner of a stream's input (SequenceInput).
struct FrameArrays {
    Image color;
    Buffers buffers;
    explicit FrameArrays(Image c) : color(std::move(c)), buffers(color) {}
};
// A frame given as a dict of arrays by buffer name (color required; albedo, normal, position,
// depth, variance, ids, emission, motion): the items of atrous.render_sequence. `at` starts its
// messages ("frame 2: ").
std::shared_ptr<FrameArrays> frameArrays(const nb::handle& frame, const std::string& at);

}  // namespace atrous::python
