// stb_image_write's implementation for the fuzz build: writePng (image_io.cpp) and make_corpus's
// seed files. Not a reader, so not under test: compiled without UBSan's shift check, which its JPEG
// writer fails (left shift of a negative value, stbiw__jpg_writeBits: `bitBuf <<= 8`).
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>
