// exr_read.cpp — the one C++ file in rouge: reads an OpenEXR image through the C++ library
// (Imf::RgbaInputFile), because OpenEXR 3.1's C core cannot decode DWA/B compression, which is what
// blender-data's HDRIs use. Tools-time only (rouge-env); the renderer never links OpenEXR. C interface in
// exr_read.h; exceptions become an error message.
#include "exr_read.h"

#include <Iex.h>
#include <ImfArray.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfRgbaFile.h>
#include <openexr.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstdint>
#include <cstring>
#include <exception>

namespace {

// The file's bytes as an input stream: every read is bounds-checked, so a truncated file is an exception,
// never a read past the buffer.
class MemoryStream : public Imf::IStream {
  public:
    MemoryStream(const char *name, const char *data, uint64_t len) : Imf::IStream(name), data_(data), len_(len) {}
    bool read(char c[], int n) override
    {
        if (n < 0 || pos_ > len_ || (uint64_t)n > len_ - pos_) throw Iex::InputExc("the file ends early (truncated)");
        std::memcpy(c, data_ + pos_, (size_t)n);
        pos_ += (uint64_t)n;
        return pos_ < len_;
    }
    uint64_t tellg() override { return pos_; }
    void seekg(uint64_t pos) override { pos_ = pos; }

  private:
    const char *data_;
    uint64_t len_, pos_ = 0;
};

// The header through OpenEXR's C core first: it checks every attribute against the file's size (the C++
// library allocates an unknown attribute's claimed size before reading it: a 300-byte file claiming 1.8 GB
// made it allocate that, found by fuzz_envmap) and the data window against the same cap. Only a header the
// core accepts reaches the C++ decoder (which alone decodes DWA in 3.1).
struct CoreCheck {
    const char *data;
    uint64_t len;
    char msg[256];
};

int64_t core_read(exr_const_context_t, void *user, void *buf, uint64_t sz, uint64_t off, exr_stream_error_func_ptr_t)
{
    const CoreCheck *c = static_cast<const CoreCheck *>(user);
    if (off >= c->len) return 0;
    uint64_t n = std::min(sz, c->len - off);
    std::memcpy(buf, c->data + off, (size_t)n);
    return (int64_t)n;
}

int64_t core_size(exr_const_context_t, void *user) { return (int64_t) static_cast<const CoreCheck *>(user)->len; }

void core_error(exr_const_context_t ctx, exr_result_t, const char *msg)
{
    void *user = nullptr;
    if (exr_get_user_data(ctx, &user) == EXR_ERR_SUCCESS && user) {
        CoreCheck *c = static_cast<CoreCheck *>(user);
        if (!c->msg[0]) std::snprintf(c->msg, sizeof c->msg, "%s", msg);
    }
}

bool core_header_ok(const char *name, const void *data, size_t len, int cap, char *msg, size_t msg_cap)
{
    CoreCheck c = {static_cast<const char *>(data), len, ""};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.user_data = &c;
    init.read_fn = core_read;
    init.size_fn = core_size;
    init.error_handler_fn = core_error;
    init.max_image_width = init.max_image_height = cap;
    init.max_tile_width = init.max_tile_height = cap;
    exr_context_t ctx = nullptr;
    exr_result_t rv = exr_start_read(&ctx, name, &init);
    if (ctx) exr_finish(&ctx);
    if (rv == EXR_ERR_SUCCESS) return true;
    std::snprintf(msg, msg_cap, "%s", c.msg[0] ? c.msg : exr_get_default_error_message(rv));
    return false;
}

// Rows decoded per readPixels call: the staging buffer stays small whatever the image's height.
const long long band_rows = 64;

}  // namespace

extern "C" int rs_exr_read_memory(const void *data, size_t len, const char *name, long long max_width, int *out_w, int *out_h,
                                  float **out_rgb, char *msg, size_t msg_cap)
{
    *out_rgb = nullptr;
    float *rgb = nullptr;
    try {
        // The library's own sanity check refuses larger data windows and tiles while it reads the header,
        // before it sizes its chunk tables from them (a 100-byte file may claim 2^31 rows).
        int cap = (int)std::min(max_width, (long long)INT32_MAX);
        Imf::Header::setMaxImageSize(cap, cap);
        Imf::Header::setMaxTileSize(cap, cap);
        if (!core_header_ok(name, data, len, cap, msg, msg_cap)) return 1;
        MemoryStream stream(name, static_cast<const char *>(data), len);
        // One thread: the tool is not time-critical and the fuzz harness wants determinism.
        Imf::RgbaInputFile in(stream, 0);
        Imath::Box2i dw = in.dataWindow();
        long long w = (long long)dw.max.x - dw.min.x + 1, h = (long long)dw.max.y - dw.min.y + 1;
        *out_w = (int)std::max(std::min(w, (long long)INT32_MAX), (long long)INT32_MIN);
        *out_h = (int)std::max(std::min(h, (long long)INT32_MAX), (long long)INT32_MIN);
        // The caller's limits hold before any pixel memory is allocated.
        if (w <= 0 || h <= 0 || w > max_width || w != 2 * h) return 2;
        rgb = (float *)std::malloc((size_t)w * (size_t)h * 3 * sizeof(float));
        Imf::Array2D<Imf::Rgba> band(std::min(band_rows, h), w);
        if (!rgb) {
            std::snprintf(msg, msg_cap, "out of memory for %lldx%lld pixels", w, h);
            return 1;
        }
        for (long long y0 = 0; y0 < h; y0 += band_rows) {
            long long rows = std::min(band_rows, h - y0);
            // The frame buffer is addressed by absolute pixel coordinates: shift the base so that
            // (dw.min.x, dw.min.y + y0) lands on band[0][0].
            // (integer arithmetic: the shifted pointer may lie far outside the buffer, as the API intends).
            uintptr_t shift = ((uintptr_t)(intptr_t)dw.min.x + (uintptr_t)(intptr_t)(dw.min.y + y0) * (uintptr_t)w) *
                              sizeof(Imf::Rgba);
            Imf::Rgba *base = reinterpret_cast<Imf::Rgba *>(reinterpret_cast<uintptr_t>(&band[0][0]) - shift);
            in.setFrameBuffer(base, 1, (size_t)w);
            in.readPixels((int)(dw.min.y + y0), (int)(dw.min.y + y0 + rows - 1));
            for (long long y = 0; y < rows; y++)
                for (long long x = 0; x < w; x++) {
                    const Imf::Rgba &p = band[y][x];
                    float *o = rgb + ((size_t)(y0 + y) * (size_t)w + (size_t)x) * 3;
                    o[0] = p.r, o[1] = p.g, o[2] = p.b;
                }
        }
        *out_rgb = rgb;
        return 0;
    } catch (const std::exception &e) {
        std::snprintf(msg, msg_cap, "%s", e.what());
    } catch (...) {
        std::snprintf(msg, msg_cap, "unknown OpenEXR error");
    }
    std::free(rgb);
    return 1;
}
