/* atrous's C API (C99; libatrous.so, link with -latrous): the shape of Intel Open Image Denoise's.
 *
 *   AtrousDevice d = atrousNewDevice("cpu");            // "cpu", "cuda" or "default"
 *   AtrousFilter f = atrousNewFilter(d, "eaw");          // a method's name; NULL or "" = the default
 *   atrousSetFilterImage(f, "color", rgb, ATROUS_FORMAT_FLOAT3, w, h, 0, 0, 0);
 *   atrousSetFilterImage(f, "output", out, ATROUS_FORMAT_FLOAT3, w, h, 0, 0, 0);
 *   atrousSetFilterInt(f, "levels", 5);                  // by the parameter table's name
 *   atrousCommitFilter(f);
 *   atrousExecuteFilter(f);
 *   const char* message;
 *   if (atrousGetDeviceError(d, &message) != ATROUS_ERROR_NONE) fprintf(stderr, "%s\n", message);
 *   atrousReleaseFilter(f);
 *   atrousReleaseDevice(d);
 *
 * No call aborts the program or lets an exception out: a failing call records an error on its
 * device (the first since the last atrousGetDeviceError) and changes nothing; a call on a NULL
 * handle, or an atrousNewDevice that fails, records it where atrousGetDeviceError(NULL, ...) reads
 * it (per thread). docs/cpp.md, "The C API", has the whole story. */
#ifndef ATROUS_ATROUS_H
#define ATROUS_ATROUS_H

#include <stdbool.h>
#include <stddef.h>

#if defined(__GNUC__) || defined(__clang__)
#define ATROUS_API __attribute__((visibility("default")))
#else
#define ATROUS_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Reference-counted handles: New* returns one reference, Retain* adds one, Release* drops one; the
 * object goes when none is left (a filter holds a reference to its device). Releasing NULL does
 * nothing, as free(NULL). */
typedef struct AtrousDeviceImpl* AtrousDevice;
typedef struct AtrousFilterImpl* AtrousFilter;

typedef enum AtrousError {
    ATROUS_ERROR_NONE = 0,
    ATROUS_ERROR_UNKNOWN = 1,              /* anything else (a CUDA failure, ...) */
    ATROUS_ERROR_INVALID_ARGUMENT = 2,     /* a NULL pointer, a bad name, format, stride, size or value */
    ATROUS_ERROR_INVALID_OPERATION = 3,    /* executing a filter that is not committed, ... */
    ATROUS_ERROR_OUT_OF_MEMORY = 4,
    ATROUS_ERROR_UNSUPPORTED_HARDWARE = 5  /* "cuda" without a usable GPU, a method without a CUDA path */
} AtrousError;

/* A pixel's element type and channel count (the values are OIDN's). The FLOAT4 / HALF4 fourth
 * channel (alpha) is not read, and not written in the output. */
typedef enum AtrousFormat {
    ATROUS_FORMAT_UNDEFINED = 0,
    ATROUS_FORMAT_FLOAT = 1,
    ATROUS_FORMAT_FLOAT2 = 2,
    ATROUS_FORMAT_FLOAT3 = 3,
    ATROUS_FORMAT_FLOAT4 = 4,
    ATROUS_FORMAT_HALF = 0x101, /* IEEE 754 binary16 */
    ATROUS_FORMAT_HALF2 = 0x102,
    ATROUS_FORMAT_HALF3 = 0x103,
    ATROUS_FORMAT_HALF4 = 0x104
} AtrousFormat;

/* ---- devices ---------------------------------------------------------------------------------- */

/* "cpu", "cuda", or "default" (also NULL or ""): cuda when this build has the CUDA backend and a
 * GPU is present, else cpu. NULL on failure ("cuda" without a usable GPU:
 * ATROUS_ERROR_UNSUPPORTED_HARDWARE; another word: ATROUS_ERROR_INVALID_ARGUMENT), the error then
 * read with atrousGetDeviceError(NULL, ...). */
ATROUS_API AtrousDevice atrousNewDevice(const char* type);
ATROUS_API void atrousRetainDevice(AtrousDevice device);
ATROUS_API void atrousReleaseDevice(AtrousDevice device);
/* "cpu" or "cuda": what the device runs on ("default" resolved); NULL for a NULL device. */
ATROUS_API const char* atrousGetDeviceType(AtrousDevice device);
/* The first error recorded on `device` since the last call, which clears it; 0
 * (ATROUS_ERROR_NONE) when there was none. `message` (may be NULL) receives its text, naming the
 * function and the argument ("" when none), valid until the next call for that device. NULL
 * device: this thread's errors of calls that had no device. */
ATROUS_API AtrousError atrousGetDeviceError(AtrousDevice device, const char** message);

/* ---- filters ---------------------------------------------------------------------------------- */

/* A filter running `method`, a name of atrous's still methods (eaw, sure, learned, blend, auto and
 * any registered one: `atrous denoise --help`); NULL or "" = "auto", the default. NULL on failure
 * (an unknown name: ATROUS_ERROR_INVALID_ARGUMENT). Its parameters start at their defaults. */
ATROUS_API AtrousFilter atrousNewFilter(AtrousDevice device, const char* method);
ATROUS_API void atrousRetainFilter(AtrousFilter filter);
ATROUS_API void atrousReleaseFilter(AtrousFilter filter);

/* Borrows an image in host memory (the caller keeps it alive until the filter no longer uses it;
 * on a "cuda" device the library copies it to the GPU). The argument order is
 * oidnSetSharedFilterImage's: element (x, y, c) is at (char*)ptr + byteOffset + y * rowByteStride +
 * x * pixelByteStride + c * the element's size. 0 strides = packed. `name`: "color" (required),
 * "variance", "albedo", "normal", "position", "depth", "ids" (object id; a second channel = the
 * material id), "emission" (the buffers' conventions: include/atrous/buffers.h), and "output",
 * the image written (RGB; it may be the colour's memory). color, variance, albedo and emission
 * take 1 channel (grey) or 3; normal and position 3; depth's first channel is read, ids' first two.
 * The data and the strides must be multiples of the element's size. */
ATROUS_API void atrousSetFilterImage(AtrousFilter filter, const char* name, void* ptr, AtrousFormat format, size_t width,
                                     size_t height, size_t byteOffset, size_t pixelByteStride, size_t rowByteStride);
ATROUS_API void atrousUnsetFilterImage(AtrousFilter filter, const char* name);

/* A parameter by its name in atrous's table (`atrous denoise --help`, docs/denoising.md:
 * "levels", "sigma_normal", "firefly", ...). Int sets integer parameters (and float ones, and
 * booleans with 0 or 1), Float float ones, Bool booleans; String the choice "sure_mode"
 * ("discrete", "james-stein") and the list "sure_candidates" ("0,0.5,1"). A value out of the
 * parameter's range is an ATROUS_ERROR_INVALID_ARGUMENT naming it, and is not set. */
ATROUS_API void atrousSetFilterInt(AtrousFilter filter, const char* name, int value);
ATROUS_API void atrousSetFilterFloat(AtrousFilter filter, const char* name, float value);
ATROUS_API void atrousSetFilterBool(AtrousFilter filter, const char* name, bool value);
ATROUS_API void atrousSetFilterString(AtrousFilter filter, const char* name, const char* value);

/* A parameter's value, or what the last atrousExecuteFilter did: Float "milliseconds" (the
 * filter's time), Int "nonfinite_pixels", "fireflies_clamped", Bool "noise_estimated" (no variance
 * was given or it was all zero), String "method" (the method that ran: what "auto" resolved to)
 * and "buffers" (those it used, "color,albedo,normal"). A String stays valid until the filter's
 * next call. 0 / false / NULL and an error for an unknown name. */
ATROUS_API int atrousGetFilterInt(AtrousFilter filter, const char* name);
ATROUS_API float atrousGetFilterFloat(AtrousFilter filter, const char* name);
ATROUS_API bool atrousGetFilterBool(AtrousFilter filter, const char* name);
ATROUS_API const char* atrousGetFilterString(AtrousFilter filter, const char* name);

/* Checks the filter as set: a colour and an output, every image of the colour's size, the
 * parameters together, the method on this device. Every change (a Set or Unset call, failed or
 * not) un-commits the filter. */
ATROUS_API void atrousCommitFilter(AtrousFilter filter);
/* Denoises: reads the images, writes "output". Synchronous. An error (a filter not committed,
 * colour values out of range, ...) leaves the output untouched. */
ATROUS_API void atrousExecuteFilter(AtrousFilter filter);

#ifdef __cplusplus
}
#endif

#endif /* ATROUS_ATROUS_H */
