// rouge_cpubench.c — the CPU-side work of a page, timed: decoding a .rsf from memory and brush stamps.
// Built twice from this one file: natively (build/rouge-cpubench) and as WebAssembly run by node
// (build/web-bench/cpubench.js, by `make web`), so tools/bench.sh can print the wasm/native ratio of the
// same work in one run. Prints `decode_ms X` and `stamp_us Y` (medians).
//
//   rouge-cpubench assets/face.rsf [RUNS]
#include "bench_kernels.h"
#include "core/core.h"

#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: rouge-cpubench FACE.rsf [RUNS]\n");
        return 2;
    }
    int runs = argc > 2 ? atoi(argv[2]) : 5;
    if (runs < 1 || runs > 64) runs = 5;
    rs_error err = {0};
    void *data = NULL;
    size_t len = 0;
    if (rs_file_read_all(argv[1], (size_t)1 << 30, &data, &len, &err) != RS_OK) {
        fprintf(stderr, "rouge-cpubench: %s\n", err.msg);
        return 1;
    }
    double ms[64];
    rs_splat_cloud *cloud = NULL;
    for (int i = 0; i < runs; i++) {
        rs_splat_destroy(cloud);
        cloud = NULL;
        double t0 = rs_time_now();
        if (rs_splat_load_memory(data, len, &cloud, &err) != RS_OK) {
            fprintf(stderr, "rouge-cpubench: %s\n", err.msg);
            free(data);
            return 1;
        }
        ms[i] = (rs_time_now() - t0) * 1000.0;
    }
    free(data);
    printf("decode_ms %.2f\n", bench_median(ms, runs));

    enum { STAMPS = 256 };
    static double us[STAMPS], touched[STAMPS];
    rs_makeup *mk = NULL;
    uint32_t *cand = NULL;
    uint32_t ncand = bench_face_candidates(cloud, &cand);
    rs_result r = rs_makeup_create(cloud, NULL, &mk, &err);
    if (r == RS_OK) r = bench_stamps(cloud, mk, cand, ncand, 0.2f, STAMPS, us, touched, &err);
    if (r == RS_OK) printf("stamp_us %.1f\n", bench_median(us, STAMPS));
    else fprintf(stderr, "rouge-cpubench: %s\n", err.msg);
    rs_makeup_destroy(mk);
    free(cand);
    rs_splat_destroy(cloud);
    return r == RS_OK ? 0 : 1;
}
