/* What a C engine gains from the product sampler: a glossy sphere under a sky with a sun,
 * shaded first with the engine's own MIS of environment sampling and BRDF sampling (written
 * here on the ABI's env-only sampler and the BRDF's own sampler, as an engine already has
 * them), then with product-MIS and two-level-MIS through the ABI, each against a converged
 * reference at several sample counts, timed by CPU time (docs/embedding.md, "Beyond the
 * anchors", holds a measured table).
 *
 *   cargo build --release -p sampler-capi
 *   cc -std=c99 -O2 -Wall -Wextra -pedantic examples/c/glossy.c -Isampler-capi/include \
 *      target/release/libsampler_capi.a -lm -lpthread -ldl -o glossy && ./glossy
 *
 * `./glossy --quick` runs a small version in a second (sampler-capi/tests/integration/examples.rs runs it).
 * Each method's errors must average out to zero against the reference (a z-test over every
 * shading point and run): the program prints FAIL and exits 1 when one does not. */
#define _POSIX_C_SOURCE 199309L
#include "ppis.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define PI 3.14159265358979323846

#define CHECK(call)                                                                   \
    do {                                                                              \
        ppis_status status_ = (call);                                                 \
        if (status_ != PPIS_OK) {                                                     \
            fprintf(stderr, "%s:%d: %s failed (%d)\n", __FILE__, __LINE__, #call, (int)status_); \
            exit(1);                                                                  \
        }                                                                             \
    } while (0)

static void *object(size_t size, size_t align) {
    void *p = malloc(size);
    if (p == NULL || (uintptr_t)p % align != 0) {
        fprintf(stderr, "cannot place an object of %zu bytes aligned to %zu\n", size, align);
        exit(1);
    }
    return p;
}

/* ---- Uniform numbers: splitmix64, independent per shading point and run. ---- */

static uint64_t splitmix(uint64_t *state) {
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static double uniform(uint64_t *state) { return (double)(splitmix(state) >> 11) * 0x1.0p-53; }

/* ---- Vectors and frames. ---- */

static ppis_vec3 vec3(double x, double y, double z) {
    ppis_vec3 v = {(float)x, (float)y, (float)z};
    return v;
}

static ppis_vec3 mul(ppis_vec3 a, ppis_vec3 b) { return vec3(a.x * b.x, a.y * b.y, a.z * b.z); }

static double luminance(ppis_vec3 c) { return 0.212671 * c.x + 0.715160 * c.y + 0.072169 * c.z; }

static ppis_vec3 to_world(const ppis_frame *f, ppis_vec3 v) {
    return vec3(f->s.x * v.x + f->t.x * v.y + f->n.x * v.z, f->s.y * v.x + f->t.y * v.y + f->n.y * v.z,
                f->s.z * v.x + f->t.z * v.y + f->n.z * v.z);
}

static ppis_vec3 to_local(const ppis_frame *f, ppis_vec3 v) {
    return vec3(f->s.x * v.x + f->s.y * v.y + f->s.z * v.z, f->t.x * v.x + f->t.y * v.y + f->t.z * v.z,
                f->n.x * v.x + f->n.y * v.y + f->n.z * v.z);
}

static double cpu_seconds(void) {
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* ---- The sky: a blue gradient, a dark ground, a glow and a sun 0.6 degrees across at 30
 * degrees elevation, in the lat-long convention of ppis_latlong_to_equal_area. ---- */

static ppis_vec3 latlong_dir(double u, double v) {
    double theta = PI * v, phi = 2.0 * PI * u;
    return vec3(sin(theta) * sin(phi), cos(theta), -sin(theta) * cos(phi));
}

static float *sky(int w, int h, ppis_vec3 sun) {
    float *texels = object((size_t)w * (size_t)h * 3 * sizeof(float), sizeof(float));
    double sun_cos = cos(0.3 * PI / 180.0);
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            ppis_vec3 d = latlong_dir((i + 0.5) / w, (j + 0.5) / h);
            double c = d.x * sun.x + d.y * sun.y + d.z * sun.z, r, g, b;
            if (c >= sun_cos) {
                r = 60000.0, g = 57000.0, b = 51000.0;
            } else if (d.y < 0.0) {
                r = g = b = 0.08;
            } else {
                double zenith = 0.4 + 0.6 * d.y, glow = 3.0 * exp((c - 1.0) / 0.02);
                r = 0.35 * (1.0 - 0.5 * zenith) + glow, g = 0.55 * (1.0 - 0.3 * zenith) + 0.9 * glow,
                b = 1.0 * zenith + 0.7 * glow;
            }
            float *p = texels + 3 * ((size_t)j * (size_t)w + (size_t)i);
            p[0] = (float)r, p[1] = (float)g, p[2] = (float)b;
        }
    return texels;
}

/* ---- One shading point's estimators: `pairs` samples of the environment side and as many of
 * the BRDF, balance heuristic. The environment side is the env-only sampler (the engine's own
 * MIS), a product built at the point, or a two-level product built at the point. ---- */

enum method { ENV_MIS, PRODUCT_MIS, TWO_LEVEL_MIS, METHODS };
static const char *const NAMES[METHODS] = {"env+BRDF MIS (host)", "product-MIS", "two-level-MIS"};

typedef struct {
    const ppis_env *env;
    const ppis_brdf *brdf;
    const ppis_cones *cones;
    ppis_product *product;
    ppis_two_level *two_level;
    ppis_product_params params;
    ppis_sample *drawn;
    double *u;
} shading;

static float side_pdf(const shading *s, enum method m, ppis_vec3 dir) {
    switch (m) {
    case PRODUCT_MIS: return ppis_product_pdf(s->product, dir);
    case TWO_LEVEL_MIS: return ppis_two_level_pdf(s->two_level, dir);
    default: return ppis_env_pdf(s->env, dir);
    }
}

static double estimate(const shading *s, enum method m, ppis_vec3 normal, ppis_vec3 wo, int pairs, uint64_t seed) {
    ppis_frame frame = ppis_frame_from_normal(normal);
    ppis_vec3 wo_local = to_local(&frame, wo);
    uint64_t rng = seed;
    for (int k = 0; k < 2 * pairs; k++) s->u[k] = uniform(&rng);
    if (m == PRODUCT_MIS) {
        CHECK(ppis_product_build(s->product, s->env, s->brdf, &frame, wo, &s->params, splitmix(&rng)));
        CHECK(ppis_product_sample_many(s->product, s->u, (size_t)pairs, s->drawn));
    } else if (m == TWO_LEVEL_MIS) {
        CHECK(ppis_two_level_build(s->two_level, s->env, s->cones, s->brdf, &frame, wo));
        CHECK(ppis_two_level_sample_many(s->two_level, s->u, (size_t)pairs, s->drawn));
    } else {
        for (int k = 0; k < pairs; k++) ppis_env_sample(s->env, s->u[2 * k], s->u[2 * k + 1], &s->drawn[k]);
    }
    double sum = 0.0;
    for (int k = 0; k < pairs; k++) {
        ppis_sample d = s->drawn[k];
        if (d.pdf > 0.0f) {
            ppis_vec3 wi = to_local(&frame, d.dir);
            double p = d.pdf + ppis_brdf_pdf(s->brdf, wo_local, wi);
            sum += luminance(mul(ppis_brdf_eval(s->brdf, wo_local, wi), ppis_env_radiance_at(s->env, d.uv))) / p;
        }
        ppis_vec2 v = {(float)uniform(&rng), (float)uniform(&rng)};
        ppis_vec3 wi, value;
        float pb;
        if (ppis_brdf_sample(s->brdf, wo_local, v, &wi, &value, &pb) == PPIS_OK) {
            ppis_vec3 dir = to_world(&frame, wi);
            sum += luminance(mul(value, ppis_env_radiance(s->env, dir))) / (pb + side_pdf(s, m, dir));
        }
    }
    return sum / pairs;
}

/* ---- The experiment. ---- */

/* Pairs one estimate draws at most (a reference batch). */
#define MAX_PAIRS 4096
#define REFERENCE_BATCHES 16

typedef struct {
    int grid, width, height, runs, reference_pairs, budgets, pairs[8];
} settings;

/* The sphere's visible normals on a grid across its disk, seen from `view` (orthographic). */
static int normals(int grid, ppis_vec3 view, ppis_vec3 *out) {
    ppis_frame f = ppis_frame_from_normal(view);
    int n = 0;
    for (int j = 0; j < grid; j++)
        for (int i = 0; i < grid; i++) {
            double a = 2.0 * (i + 0.5) / grid - 1.0, b = 2.0 * (j + 0.5) / grid - 1.0, r2 = a * a + b * b;
            if (r2 < 0.96) out[n++] = to_world(&f, vec3(a, b, sqrt(1.0 - r2)));
        }
    return n;
}

/* `error[m][b]`: mean squared error over points and runs, less the reference's own variance
 * (independent of the estimates, it adds to every method's squared error alike); `seconds[m][b]`:
 * CPU seconds per shading point. Returns 0 when a method's errors do not average out. */
static int measure(const settings *cfg, shading *s, const ppis_vec3 *n, int points, ppis_vec3 wo,
                   double error[METHODS][8], double seconds[METHODS][8], double *mean_ref, double *ref_rel_se) {
    double *ref = malloc(sizeof(double) * (size_t)points), ref_sum = 0.0, ref_var = 0.0;
    for (int p = 0; p < points; p++) {
        /* The reference: the engine's MIS with many samples, as batches for its standard error. */
        enum { BATCHES = REFERENCE_BATCHES };
        double b[BATCHES], m = 0.0, v = 0.0;
        for (int k = 0; k < BATCHES; k++) {
            b[k] = estimate(s, ENV_MIS, n[p], wo, cfg->reference_pairs / BATCHES, 0x5eed0000ull + (uint64_t)(p * BATCHES + k));
            m += b[k] / BATCHES;
        }
        for (int k = 0; k < BATCHES; k++) v += (b[k] - m) * (b[k] - m) / ((double)BATCHES * (BATCHES - 1));
        ref[p] = m, ref_sum += m, ref_var += v;
    }
    *mean_ref = ref_sum / points;
    double ref_mse = ref_var / points;
    *ref_rel_se = sqrt(ref_var / points) / *mean_ref;
    int pass = 1;
    for (int m = 0; m < METHODS; m++) {
        double sum_e = 0.0, sum_e2 = 0.0;
        for (int b = 0; b < cfg->budgets; b++) {
            double se = 0.0, t0 = cpu_seconds();
            double *est = malloc(sizeof(double) * (size_t)points * (size_t)cfg->runs);
            for (int r = 0; r < cfg->runs; r++)
                for (int p = 0; p < points; p++)
                    est[r * points + p] = estimate(s, (enum method)m, n[p], wo, cfg->pairs[b],
                                                   ((uint64_t)(r * 8 + b) << 32) + (uint64_t)p);
            seconds[m][b] = (cpu_seconds() - t0) / ((double)points * cfg->runs);
            for (int r = 0; r < cfg->runs; r++)
                for (int p = 0; p < points; p++) {
                    double e = est[r * points + p] - ref[p];
                    se += e * e, sum_e += e, sum_e2 += e * e;
                }
            error[m][b] = fmax(se / ((double)points * cfg->runs) - ref_mse, 1e-3 * ref_mse);
            free(est);
        }
        double z = sum_e / sqrt(sum_e2);
        if (!(fabs(z) < 4.0)) {
            printf("FAIL: %s's errors average %g (z = %.2f)\n", NAMES[m], sum_e, z);
            pass = 0;
        }
    }
    free(ref);
    return pass;
}

/* log MSE of method `m` at CPU time `t`, interpolated in log-log between its budgets and
 * extrapolated beyond the largest with slope -1 (MSE proportional to 1/time once the build is
 * amortised); NAN below its smallest budget's time, which its build alone may exceed. */
static double log_error_at(const settings *cfg, double error[METHODS][8], double seconds[METHODS][8], int m,
                           double t) {
    int b = 0;
    while (b + 2 < cfg->budgets && seconds[m][b + 1] < t) b++;
    double x0 = log(seconds[m][b]), x1 = log(seconds[m][b + 1]), y0 = log(error[m][b]), y1 = log(error[m][b + 1]);
    double x = log(t);
    if (x < log(seconds[m][0])) return NAN;
    if (x < x0) return y0 - (x - x0);
    if (x > x1) return y1 - (x - x1);
    return y0 + (y1 - y0) * (x - x0) / (x1 - x0);
}

static void report(const settings *cfg, const char *material, double error[METHODS][8], double seconds[METHODS][8],
                   double mean_ref) {
    for (int b = 0; b < cfg->budgets; b++) {
        printf("| %s | %d |", material, 2 * cfg->pairs[b]);
        for (int m = 0; m < METHODS; m++)
            printf(" %.1f µs, %.4f |", 1e6 * seconds[m][b], sqrt(error[m][b]) / mean_ref);
        /* Equal time: the others' MSE at the host MIS's CPU time. */
        for (int m = 1; m < METHODS; m++) {
            double other = log_error_at(cfg, error, seconds, m, seconds[ENV_MIS][b]);
            if (isnan(other))
                printf(" — |");
            else
                printf(" %.2f× |", exp(log(error[ENV_MIS][b]) - other));
        }
        printf("\n");
    }
}

int main(int argc, char **argv) {
    int quick = argc > 1 && strcmp(argv[1], "--quick") == 0;
    settings full = {20, 1024, 512, 16, MAX_PAIRS * REFERENCE_BATCHES, 5, {2, 8, 32, 128, 512}};
    settings small = {6, 256, 128, 2, 1 << 11, 2, {2, 8}};
    const settings *cfg = quick ? &small : &full;

    /* The sun 30 degrees up, a tenth of a turn from +X towards +Z. */
    double elevation = 30.0 * PI / 180.0;
    ppis_vec3 sun = latlong_dir(0.3, 0.5 - elevation / PI);
    float *latlong = sky(cfg->width, cfg->height, sun);
    uint32_t level = ppis_equal_area_level((uint32_t)cfg->width, (uint32_t)cfg->height);
    size_t texels = (size_t)1 << (2 * level), pyramid_len = ppis_pyramid_len(level);
    float *rgb = object(texels * 3 * sizeof(float), sizeof(float));
    float *pyramid = object(pyramid_len * sizeof(float), sizeof(float));
    CHECK(ppis_latlong_to_equal_area(latlong, (uint32_t)cfg->width, (uint32_t)cfg->height, level, 2, rgb, texels * 3));
    ppis_sanitize_rgb(rgb, texels);
    CHECK(ppis_build_pyramid(level, rgb, texels * 3, pyramid, pyramid_len));

    shading s;
    ppis_env *env;
    CHECK(ppis_env_init(object(ppis_env_size(), ppis_env_align()), ppis_env_size(), level, pyramid, pyramid_len, rgb,
                        texels * 3, &env));
    ppis_cones *cones;
    CHECK(ppis_cones_init(object(ppis_cones_size(4), ppis_cones_align()), ppis_cones_size(4), 4, &cones));
    s.env = env, s.cones = cones, s.params = ppis_product_params_for_mis(64);
    CHECK(ppis_product_init(object(ppis_product_size(), ppis_product_align()), ppis_product_size(), &s.product));
    CHECK(ppis_two_level_init(object(ppis_two_level_size(), ppis_two_level_align()), ppis_two_level_size(),
                              &s.two_level));
    s.drawn = object(sizeof(ppis_sample) * MAX_PAIRS, sizeof(double));
    s.u = object(sizeof(double) * 2 * MAX_PAIRS, sizeof(double));

    ppis_vec3 wo = vec3(0.0, 0.2, 0.98), n[400];
    double len = sqrt(wo.x * wo.x + wo.y * wo.y + wo.z * wo.z);
    wo = vec3(wo.x / len, wo.y / len, wo.z / len);
    int points = normals(cfg->grid, wo, n);

    enum { MATERIALS = 3 };
    const char *materials[MATERIALS] = {"GGX α = 0.05", "GGX α = 0.2", "car paint"};
    ppis_brdf *brdf[MATERIALS];
    void *mem[MATERIALS];
    for (int k = 0; k < MATERIALS; k++) mem[k] = object(ppis_brdf_size(), ppis_brdf_align());
    ppis_vec3 gold = vec3(1.0, 0.78, 0.34);
    CHECK(ppis_brdf_init_conductor(mem[0], ppis_brdf_size(), 0.05f, gold, &brdf[0]));
    CHECK(ppis_brdf_init_conductor(mem[1], ppis_brdf_size(), 0.2f, gold, &brdf[1]));
    CHECK(ppis_brdf_init_carpaint(mem[2], ppis_brdf_size(), vec3(0.02, 0.05, 0.25), vec3(0.2, 0.3, 0.6), 0.3f, 1.0f,
                                  0.03f, &brdf[2]));

    printf("%d shading points, map level %u, %d runs, reference %d samples per point\n\n", points, level, cfg->runs,
           cfg->reference_pairs);
    printf("| material | samples | host MIS: CPU per point, rel. RMSE | product-MIS | two-level-MIS |"
           " MSE ratio at equal time: host / product-MIS | host / two-level-MIS |\n");
    printf("|---|---:|---:|---:|---:|---:|---:|\n");
    int pass = 1;
    double error[METHODS][8], seconds[METHODS][8], ref_se[MATERIALS];
    for (int k = 0; k < MATERIALS; k++) {
        double mean_ref, ref_rel_se;
        s.brdf = brdf[k];
        pass &= measure(cfg, &s, n, points, wo, error, seconds, &mean_ref, &ref_rel_se);
        report(cfg, materials[k], error, seconds, mean_ref);
        ref_se[k] = ref_rel_se;
    }
    printf("\nThe reference's relative standard error:");
    for (int k = 0; k < MATERIALS; k++) printf(" %s %.4f%s", materials[k], ref_se[k], k + 1 < MATERIALS ? "," : ".\n");
    printf("%s\n", pass ? "PASS" : "FAIL");
    return pass ? 0 : 1;
}
