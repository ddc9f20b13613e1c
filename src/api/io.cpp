// The public reading of a render's files (include/atrous/io.h) over the buffer assembly; readImage
// and writeImage themselves are src/io/image_io.cpp's.
#include "atrous/io.h"

#include "atrous/io/buffer_set.h"
#include "atrous/io/image_io.h"
#include "atrous/io/pass_map.h"

namespace atrous {

const Image* RenderFiles::get(const std::string& name) const {
    for (const auto& [n, img] : buffers)
        if (n == name) return &img;
    return nullptr;
}

RenderFiles readRenderFiles(const std::string& path, const std::vector<std::string>& passes,
                            const std::string& viewLayer) {
    io::BufferFiles files;
    files.in = path;
    files.passes = io::parsePassRequests(passes);
    files.viewLayer = viewLayer;
    io::BufferSet set = io::loadBuffers(files);
    RenderFiles out;
    for (int i = 0; i < io::kBufferCount; ++i) {
        const io::Buffer b = io::Buffer(i);
        if (b == io::Buffer::MaterialId || set.image[i].empty()) continue;  // the ids live in the object_id slot
        const std::string name = b == io::Buffer::ObjectId ? "ids" : io::bufferName(b);
        out.from.emplace_back(name, set.from[i]);
        out.buffers.emplace_back(name, std::move(set.image[i]));
    }
    out.notes = std::move(set.notes);
    return out;
}

}  // namespace atrous
