// The implementations of the header-only libraries the readers call, compiled into the fuzz build
// (instrumented, so that libFuzzer's coverage and ASan reach into stb_image's decoders and
// tinyobjloader's parser). The same Debian headers the main build links as libstb.so and
// libtinyobjloader.so (float real_t, as tinyobjloader::tinyobjloader).
#define STB_IMAGE_IMPLEMENTATION
#define TINYOBJLOADER_IMPLEMENTATION
#include <stb_image.h>
#include <tiny_obj_loader.h>
