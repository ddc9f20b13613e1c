/* The C API as a C program uses it (tests/c_api_package_test.sh builds this file with
 * `cc -std=c99 -Wall -Wextra -pedantic -Werror` against the installed <atrous/atrous.h> and links it
 * to the installed libatrous.so):
 *   1. an interleaved float32 RGB colour with albedo and normal, denoised with "eaw" and with the
 *      default method, equals the CLI's `atrous denoise` of the same data (PFM files) within 1e-6
 *      relative;
 *   2. padded rows and an RGBA output (alpha left alone) give the same values;
 *   3. half precision (HALF3 in and out) matches the float run within half's rounding;
 *   4. bad input (a bad buffer name, a wrong size, an unknown method, a NULL pointer, a too-small
 *      stride, a parameter out of range, a format the buffer cannot take, colour values out of range)
 *      is an error code and a message naming the argument from atrousGetDeviceError, and the output
 *      keeps its canary pattern.
 *
 *   c_denoise ATROUS_CLI WORK_DIR       (exit 0: all passed) */
#include <atrous/atrous.h>

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define W 61
#define H 40
#define N (W * H * 3)

static float color[N], albedo[N], normal[N];
static int failures = 0;

#define CHECK(cond, ...)                                         \
    do {                                                         \
        if (!(cond)) {                                           \
            fprintf(stderr, "c_denoise: FAIL line %d: ", __LINE__); \
            fprintf(stderr, __VA_ARGS__);                        \
            fprintf(stderr, "\n");                               \
            ++failures;                                          \
        }                                                        \
    } while (0)

/* ---- test data on a 1/1024 grid, so that every value is exactly a half ------------------------ */

static uint32_t rngState = 12345u;
static float uniform01(void) {
    rngState = rngState * 1664525u + 1013904223u;
    return (float)(rngState >> 8) / 16777216.0f;
}
static float grid(float v) { return (float)floor(v * 1024.0 + 0.5) / 1024.0f; }

static void makeScene(void) {
    int x, y, c;
    for (y = 0; y < H; ++y)
        for (x = 0; x < W; ++x) {
            float* a = albedo + 3 * (y * W + x);
            float* n = normal + 3 * (y * W + x);
            float* col = color + 3 * (y * W + x);
            const int left = x < W / 2, top = y < H / 2;
            a[0] = left ? 0.8f : 0.2f, a[1] = left ? 0.3f : 0.5f, a[2] = left ? 0.2f : 0.9f;
            n[0] = 0.0f, n[1] = top ? 0.0f : 0.6f, n[2] = top ? 1.0f : 0.8f;
            for (c = 0; c < 3; ++c) {
                const float noisy = a[c] * (0.3f + 0.9f * (float)x / W) + 0.4f * (uniform01() - 0.5f);
                col[c] = grid(noisy > 0.0f ? noisy : 0.0f);
                a[c] = grid(a[c]);
                n[c] = grid(n[c]);
            }
        }
}

/* ---- half <-> float for values on the grid (exact both ways) and any half -------------------- */

static uint16_t halfOfExact(float v) {
    int e;
    const float m = (float)frexp(fabs(v), &e); /* |v| = m 2^e, m in [0.5, 1) */
    const uint16_t sign = v < 0 ? 0x8000 : 0;
    if (v == 0.0f) return sign;
    return (uint16_t)(sign | (uint16_t)((e - 1 + 15) << 10) | (uint16_t)((m * 2.0f - 1.0f) * 1024.0f));
}
static float floatOfHalf(uint16_t h) {
    const int e = (h >> 10) & 0x1f, m = h & 0x3ff;
    const float s = (h & 0x8000) ? -1.0f : 1.0f;
    if (e == 0) return s * (float)ldexp(m, -24);
    if (e == 31) return m ? NAN : s * INFINITY;
    return s * (float)ldexp(1024 + m, e - 25);
}

/* ---- PFM (what the CLI reads and writes: rows bottom to top, little-endian for a negative scale) */

static int littleEndian(void) {
    const uint16_t one = 1;
    return *(const unsigned char*)&one == 1;
}

static int writePfm(const char* path, const float* rgb) {
    int y;
    FILE* f = fopen(path, "wb");
    if (!f) return 0;
    fprintf(f, "PF\n%d %d\n-1.0\n", W, H);
    for (y = H - 1; y >= 0; --y) fwrite(rgb + 3 * W * y, sizeof(float), 3 * W, f);
    return fclose(f) == 0;
}

static int readPfm(const char* path, float* rgb) {
    char magic[3] = {0};
    int w = 0, h = 0, y, ok;
    float scale = 0;
    FILE* f = fopen(path, "rb");
    if (!f) return 0;
    ok = fscanf(f, "%2s %d %d %f", magic, &w, &h, &scale) == 4 && strcmp(magic, "PF") == 0 && w == W && h == H && scale < 0;
    ok = ok && fgetc(f) == '\n';
    for (y = H - 1; ok && y >= 0; --y) ok = fread(rgb + 3 * W * y, sizeof(float), 3 * W, f) == (size_t)(3 * W);
    fclose(f);
    return ok;
}

/* ---- running the filter ---------------------------------------------------------------------- */

static const char* lastMessage = "";

/* The device's pending error code (0 = none), its message in lastMessage. */
static int takeError(AtrousDevice d) { return (int)atrousGetDeviceError(d, &lastMessage); }

/* One image the filter reads or writes: its data, format and byte strides (0 = packed). */
typedef struct {
    void* data;
    AtrousFormat format;
    size_t pixelStride, rowStride;
} Image;

static Image packed(void* data, AtrousFormat format) {
    Image i;
    i.data = data, i.format = format, i.pixelStride = 0, i.rowStride = 0;
    return i;
}

/* The whole sequence: a filter of `method` (NULL = the default) on colour, albedo and normal,
 * written to out; 0 when an error came. */
static int run(AtrousDevice d, const char* method, Image c, Image a, Image n, Image out) {
    const char* names[4] = {"color", "albedo", "normal", "output"};
    const Image images[4] = {c, a, n, out};
    int k;
    AtrousFilter f = atrousNewFilter(d, method);
    for (k = 0; k < 4; ++k)
        atrousSetFilterImage(f, names[k], images[k].data, images[k].format, W, H, 0, images[k].pixelStride, images[k].rowStride);
    atrousCommitFilter(f);
    atrousExecuteFilter(f);
    atrousReleaseFilter(f);
    if (takeError(d)) {
        fprintf(stderr, "c_denoise: %s: %s\n", method ? method : "(default)", lastMessage);
        return 0;
    }
    return 1;
}

/* The scene as packed FLOAT3 into out (packed FLOAT3). */
static int denoise(AtrousDevice d, const char* method, float* out) {
    return run(d, method, packed(color, ATROUS_FORMAT_FLOAT3), packed(albedo, ATROUS_FORMAT_FLOAT3),
               packed(normal, ATROUS_FORMAT_FLOAT3), packed(out, ATROUS_FORMAT_FLOAT3));
}

/* Largest |a - b| / max(|a|, |b|) (0 where both are 0). */
static double maxRelative(const float* a, const float* b, int n) {
    double worst = 0;
    int i;
    for (i = 0; i < n; ++i) {
        const double scale = fabs(a[i]) > fabs(b[i]) ? fabs(a[i]) : fabs(b[i]);
        const double r = scale > 0 ? fabs((double)a[i] - b[i]) / scale : 0.0;
        if (!(r <= worst)) worst = r; /* NaN counts as the worst */
    }
    return worst;
}

static void compareWithCli(AtrousDevice d, const char* cli, const char* dir, const char* method) {
    static float ours[N], theirs[N];
    char cmd[4096], out[1024];
    snprintf(out, sizeof out, "%s/cli_%s.pfm", dir, method ? method : "default");
    snprintf(cmd, sizeof cmd, "\"%s\" denoise --color %s/color.pfm --albedo %s/albedo.pfm --normal %s/normal.pfm %s%s --out %s",
             cli, dir, dir, dir, method ? "--method " : "", method ? method : "", out);
    CHECK(system(cmd) == 0, "the CLI failed: %s", cmd);
    CHECK(readPfm(out, theirs), "cannot read the CLI's %s", out);
    CHECK(denoise(d, method, ours), "the C API failed with %s", method ? method : "the default");
    {
        const double r = maxRelative(ours, theirs, N);
        printf("%-8s C API vs CLI: largest relative difference %.3g\n", method ? method : "default", r);
        CHECK(r <= 1e-6, "%s: the C API's output differs from the CLI's by %.3g relative", method ? method : "default", r);
        CHECK(maxRelative(ours, color, N) > 1e-3, "the output equals the input");
    }
}

/* The same run with padded rows (in) and an RGBA output with padded rows (alpha kept). */
static void checkLayouts(AtrousDevice d, const float* reference) {
    enum { PAD = 5, ROW = (W * 3 + PAD), OROW = (W * 4 + PAD) };
    static float padded[H * ROW], rgba[H * OROW];
    int x, y, c, alphaKept = 1;
    double worst = 0;
    Image in = packed(padded, ATROUS_FORMAT_FLOAT3), out = packed(rgba, ATROUS_FORMAT_FLOAT4);
    for (y = 0; y < H; ++y) memcpy(padded + y * ROW, color + 3 * W * y, 3 * W * sizeof(float));
    for (x = 0; x < H * OROW; ++x) rgba[x] = -7.0f;
    in.pixelStride = 12, in.rowStride = ROW * sizeof(float), out.rowStride = OROW * sizeof(float);
    CHECK(run(d, "eaw", in, packed(albedo, ATROUS_FORMAT_FLOAT3), packed(normal, ATROUS_FORMAT_FLOAT3), out),
          "padded rows / RGBA output");
    for (y = 0; y < H; ++y)
        for (x = 0; x < W; ++x) {
            for (c = 0; c < 3; ++c) {
                const double e = fabs(rgba[y * OROW + 4 * x + c] - reference[3 * (y * W + x) + c]);
                if (e > worst) worst = e;
            }
            alphaKept = alphaKept && rgba[y * OROW + 4 * x + 3] == -7.0f;
        }
    CHECK(worst == 0, "padded rows / RGBA output differ from the packed run by %g", worst);
    CHECK(alphaKept, "the RGBA output's alpha was written");
    CHECK(rgba[OROW - 1] == -7.0f, "a row's padding was written");
}

/* HALF3 in and out: the inputs are the same values (on the 1/1024 grid every one is a half), so
 * the outputs differ by the output's rounding to half only: at most half an ulp, 2^-11 relative
 * (2^-25 absolute below half's smallest normal, 2^-14). */
static void checkHalf(AtrousDevice d, const float* reference) {
    static uint16_t hc[N], ha[N], hn[N], ho[N];
    int i, bad = 0;
    double worst = 0;
    for (i = 0; i < N; ++i) {
        hc[i] = halfOfExact(color[i]), ha[i] = halfOfExact(albedo[i]), hn[i] = halfOfExact(normal[i]);
        if (floatOfHalf(hc[i]) != color[i] || floatOfHalf(ha[i]) != albedo[i] || floatOfHalf(hn[i]) != normal[i]) ++bad;
    }
    CHECK(bad == 0, "%d test values are not exactly halves", bad);
    CHECK(run(d, "eaw", packed(hc, ATROUS_FORMAT_HALF3), packed(ha, ATROUS_FORMAT_HALF3), packed(hn, ATROUS_FORMAT_HALF3),
              packed(ho, ATROUS_FORMAT_HALF3)),
          "half run");
    for (i = 0; i < N; ++i) {
        const double ref = reference[i], got = floatOfHalf(ho[i]);
        const double e = fabs(got - ref);
        if (e > ldexp(fabs(ref), -11) + ldexp(1.0, -25)) ++bad;
        if (ref != 0 && e / fabs(ref) > worst) worst = e / fabs(ref);
    }
    printf("half     HALF3 vs FLOAT3: largest relative difference %.3g (bound 2^-11 = %.3g)\n", worst, ldexp(1.0, -11));
    CHECK(bad == 0, "%d half outputs are further than half an ulp from the float run", bad);
}

/* ---- bad input ------------------------------------------------------------------------------- */

static float canary[N];

static void fillCanary(void) {
    int i;
    for (i = 0; i < N; ++i) canary[i] = -1234.5f - (float)(i % 7);
}
static int canaryIntact(void) {
    int i;
    for (i = 0; i < N; ++i)
        if (canary[i] != -1234.5f - (float)(i % 7)) return 0;
    return 1;
}

/* A filter with valid colour, albedo and output (the canary). */
static AtrousFilter validFilter(AtrousDevice d) {
    AtrousFilter f = atrousNewFilter(d, "eaw");
    atrousSetFilterImage(f, "color", color, ATROUS_FORMAT_FLOAT3, W, H, 0, 0, 0);
    atrousSetFilterImage(f, "albedo", albedo, ATROUS_FORMAT_FLOAT3, W, H, 0, 0, 0);
    atrousSetFilterImage(f, "output", canary, ATROUS_FORMAT_FLOAT3, W, H, 0, 0, 0);
    return f;
}

/* After the failing call(s): the error's code and the argument in its message, the error cleared
 * by reading it, the filter refusing to run (nothing committed), the canary intact. */
static void expectError(AtrousDevice d, AtrousFilter f, const char* what, int code, const char* named) {
    const int got = takeError(d);
    printf("bad input: %-34s -> %d: %s\n", what, got, lastMessage);
    CHECK(got == code, "%s: error %d, expected %d (%s)", what, got, code, lastMessage);
    CHECK(lastMessage && strstr(lastMessage, named), "%s: the message does not name '%s': %s", what, named, lastMessage);
    CHECK(takeError(d) == 0, "%s: reading the error did not clear it", what);
    if (f) {
        atrousExecuteFilter(f);
        CHECK(takeError(d) != 0, "%s: the filter ran after the error", what);
        atrousReleaseFilter(f);
    }
    CHECK(canaryIntact(), "%s: the output was written", what);
}

static void checkBadInput(AtrousDevice d) {
    AtrousFilter f;
    static float big[N];
    int i;
    fillCanary();

    f = validFilter(d);
    atrousSetFilterImage(f, "colour", color, ATROUS_FORMAT_FLOAT3, W, H, 0, 0, 0);
    expectError(d, f, "a buffer name that does not exist", ATROUS_ERROR_INVALID_ARGUMENT, "colour");

    f = validFilter(d);
    atrousSetFilterImage(f, "normal", normal, ATROUS_FORMAT_FLOAT3, W - 1, H, 0, 0, 0);
    atrousCommitFilter(f);
    expectError(d, f, "a wrong size", ATROUS_ERROR_INVALID_ARGUMENT, "normal");

    CHECK(atrousNewFilter(d, "nosuch") == NULL, "an unknown method gave a filter");
    expectError(d, NULL, "an unknown method", ATROUS_ERROR_INVALID_ARGUMENT, "nosuch");

    f = validFilter(d);
    atrousSetFilterImage(f, "albedo", NULL, ATROUS_FORMAT_FLOAT3, W, H, 0, 0, 0);
    expectError(d, f, "a NULL pointer", ATROUS_ERROR_INVALID_ARGUMENT, "ptr");

    atrousSetFilterInt(NULL, "levels", 3);
    CHECK(atrousGetDeviceError(NULL, &lastMessage) == ATROUS_ERROR_INVALID_ARGUMENT && strstr(lastMessage, "filter"),
          "a NULL filter: %s", lastMessage);

    f = validFilter(d);
    atrousSetFilterImage(f, "color", color, ATROUS_FORMAT_FLOAT3, W, H, 0, 8, 0);
    expectError(d, f, "a pixel stride smaller than a pixel", ATROUS_ERROR_INVALID_ARGUMENT, "pixelByteStride");

    f = validFilter(d);
    atrousSetFilterImage(f, "output", canary, ATROUS_FORMAT_FLOAT3, W, H, 0, 0, 3 * sizeof(float) * (W - 1));
    expectError(d, f, "a row stride smaller than a row", ATROUS_ERROR_INVALID_ARGUMENT, "rowByteStride");

    f = validFilter(d);
    atrousCommitFilter(f);
    atrousSetFilterInt(f, "levels", 11);
    CHECK(atrousGetFilterInt(f, "levels") == 5, "the refused value was set");
    expectError(d, f, "a parameter out of range", ATROUS_ERROR_INVALID_ARGUMENT, "levels");

    f = validFilter(d);
    atrousSetFilterFloat(f, "sigma_normal", -1.0f);
    expectError(d, f, "a float parameter out of range", ATROUS_ERROR_INVALID_ARGUMENT, "sigma_normal");

    f = validFilter(d);
    atrousSetFilterFloat(f, "no_such_parameter", 1.0f);
    expectError(d, f, "a parameter that does not exist", ATROUS_ERROR_INVALID_ARGUMENT, "no_such_parameter");

    f = validFilter(d);
    atrousSetFilterImage(f, "normal", normal, ATROUS_FORMAT_FLOAT, W, H, 0, 0, 0);
    expectError(d, f, "a format the buffer cannot take", ATROUS_ERROR_INVALID_ARGUMENT, "normal");

    f = validFilter(d);
    atrousSetFilterImage(f, "output", canary, ATROUS_FORMAT_FLOAT2, W, H, 0, 0, 0);
    expectError(d, f, "an output of two channels", ATROUS_ERROR_INVALID_ARGUMENT, "output");

    /* Committed and valid, but the colour holds a value beyond the filter's range: the library's
     * own check at execution, still before anything is written. */
    for (i = 0; i < N; ++i) big[i] = color[i];
    big[7] = 1e30f;
    f = validFilter(d);
    atrousSetFilterImage(f, "color", big, ATROUS_FORMAT_FLOAT3, W, H, 0, 0, 0);
    atrousCommitFilter(f);
    CHECK(takeError(d) == 0, "committing a valid filter: %s", lastMessage);
    atrousExecuteFilter(f);
    expectError(d, f, "colour values out of range", ATROUS_ERROR_INVALID_ARGUMENT, "color");

    f = validFilter(d);
    atrousExecuteFilter(f);
    expectError(d, f, "executing without a commit", ATROUS_ERROR_INVALID_OPERATION, "commit");

    CHECK(atrousNewDevice("gpu") == NULL, "device \"gpu\" was made");
    CHECK(atrousGetDeviceError(NULL, &lastMessage) == ATROUS_ERROR_INVALID_ARGUMENT && strstr(lastMessage, "gpu"),
          "a bad device type: %s", lastMessage);
}

int main(int argc, char** argv) {
    static float eaw[N];
    char path[1024];
    AtrousDevice d;
    if (argc != 3) {
        fprintf(stderr, "usage: c_denoise ATROUS_CLI WORK_DIR\n");
        return 2;
    }
    if (!littleEndian()) {
        fprintf(stderr, "c_denoise: the PFM files here are little-endian; this host is not\n");
        return 2;
    }
    makeScene();
    snprintf(path, sizeof path, "%s/color.pfm", argv[2]);
    CHECK(writePfm(path, color), "cannot write %s", path);
    snprintf(path, sizeof path, "%s/albedo.pfm", argv[2]);
    CHECK(writePfm(path, albedo), "cannot write %s", path);
    snprintf(path, sizeof path, "%s/normal.pfm", argv[2]);
    CHECK(writePfm(path, normal), "cannot write %s", path);

    d = atrousNewDevice("cpu");
    CHECK(d != NULL, "no cpu device");
    if (!d) return 1;
    CHECK(strcmp(atrousGetDeviceType(d), "cpu") == 0, "the device is %s", atrousGetDeviceType(d));

    compareWithCli(d, argv[1], argv[2], "eaw");
    compareWithCli(d, argv[1], argv[2], NULL);
    CHECK(denoise(d, "eaw", eaw), "eaw");
    checkLayouts(d, eaw);
    checkHalf(d, eaw);
    checkBadInput(d);
    atrousReleaseDevice(d);

    if (failures) {
        fprintf(stderr, "c_denoise: %d check(s) failed\n", failures);
        return 1;
    }
    printf("c_denoise: OK\n");
    return 0;
}
