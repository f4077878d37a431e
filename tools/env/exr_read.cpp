// exr_read.cpp — the one C++ file in rouge: reads an OpenEXR image through the C++ library
// (Imf::RgbaInputFile), because OpenEXR 3.1's C core cannot decode DWA/B compression, which is what
// blender-data's HDRIs use. Tools-time only (rouge-env); the renderer never links OpenEXR. C interface in
// exr_read.h; exceptions become an error message.
#include "exr_read.h"

#include <ImfArray.h>
#include <ImfRgbaFile.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>

extern "C" int rs_exr_read(const char *path, long long max_side, int *out_w, int *out_h, float **out_rgb, char *msg,
                           size_t msg_cap)
{
    *out_rgb = nullptr;
    try {
        Imf::RgbaInputFile in(path);
        Imath::Box2i dw = in.dataWindow();
        long long w = (long long)dw.max.x - dw.min.x + 1, h = (long long)dw.max.y - dw.min.y + 1;
        *out_w = (int)std::min(w, (long long)INT32_MAX), *out_h = (int)std::min(h, (long long)INT32_MAX);
        // The caller decides whether the size is acceptable; nothing is allocated for a refused one.
        if (w <= 0 || h <= 0 || w > max_side || h > max_side) return 2;
        Imf::Array2D<Imf::Rgba> px(h, w);
        in.setFrameBuffer(&px[0][0] - dw.min.x - dw.min.y * w, 1, (size_t)w);
        in.readPixels(dw.min.y, dw.max.y);
        float *rgb = (float *)std::malloc((size_t)w * (size_t)h * 3 * sizeof(float));
        if (!rgb) {
            std::snprintf(msg, msg_cap, "out of memory");
            return 1;
        }
        for (long long y = 0; y < h; y++)
            for (long long x = 0; x < w; x++) {
                const Imf::Rgba &p = px[y][x];
                float *o = rgb + ((size_t)y * (size_t)w + (size_t)x) * 3;
                o[0] = p.r, o[1] = p.g, o[2] = p.b;
            }
        *out_rgb = rgb;
        return 0;
    } catch (const std::exception &e) {
        std::snprintf(msg, msg_cap, "%s", e.what());
    } catch (...) {
        std::snprintf(msg, msg_cap, "unknown OpenEXR error");
    }
    return 1;
}
