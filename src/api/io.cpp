// The public image I/O (include/atrous/io.h): the internal readers and writers, which stay in
// src/io so that the CLI, tests and Python keep using them unchanged.
#include "atrous/io.h"

#include "io/image_io.h"

namespace atrous {

Image readImage(const std::string& path) {
    return io::readImage(path);
}

void writeImage(const std::string& path, const Image& img) {
    // The writers read host memory; a library user's denoise() result may live on the GPU.
    if (img.device() != Device::Cpu) {
        io::writeImage(path, img.to(Device::Cpu));
        return;
    }
    io::writeImage(path, img);
}

}  // namespace atrous
