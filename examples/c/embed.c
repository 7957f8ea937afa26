/* Embedding ppis in a C engine (C99): a lat-long sky resampled into the equal-area square, its
 * pyramid, a GGX conductor and an engine-defined BRDF given as callbacks, the quadtree and the
 * two-level product samplers of one shading point, and a product-MIS estimate of the point's
 * direct light checked against quadrature.
 *
 *   cargo build --release -p sampler-capi
 *   cc -std=c99 -O2 -Wall -Wextra -pedantic examples/c/embed.c -Isampler-capi/include \
 *      target/release/libsampler_capi.a -lm -lpthread -ldl -o embed && ./embed
 *
 * It prints the first samples of each sampler as hex floats (sampler-capi/tests/integration/examples.rs
 * compares them bit for bit with the Rust API) and exits 1 when the estimate misses. Every
 * object lives in memory this program owns; nothing is freed by the library. */
#include "ppis.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* Strict C99 has no M_PI. */
#define PI 3.14159265358979323846
#define INV_PI 0.31830988618379067154

#define CHECK(call)                                                                   \
    do {                                                                              \
        ppis_status status_ = (call);                                                 \
        if (status_ != PPIS_OK) {                                                     \
            fprintf(stderr, "%s:%d: %s failed (%d)\n", __FILE__, __LINE__, #call, (int)status_); \
            exit(1);                                                                  \
        }                                                                             \
    } while (0)

/* Memory for a library object: malloc aligns to 16 bytes, more than any object needs (checked). */
static void *object(size_t size, size_t align) {
    void *p = malloc(size);
    if (p == NULL || (uintptr_t)p % align != 0) {
        fprintf(stderr, "cannot place an object of %zu bytes aligned to %zu\n", size, align);
        exit(1);
    }
    return p;
}

/* The engine's own material: a Lambertian BRDF, as an engine would wrap its shader. */
typedef struct {
    ppis_vec3 albedo;
} lambert;

static ppis_vec3 lambert_eval(void *user, ppis_vec3 wo, ppis_vec3 wi) {
    const lambert *m = (const lambert *)user;
    ppis_vec3 zero = {0.0f, 0.0f, 0.0f};
    if (wo.z <= 0.0f || wi.z <= 0.0f) return zero;
    float k = (float)INV_PI * wi.z;
    ppis_vec3 v = {m->albedo.x * k, m->albedo.y * k, m->albedo.z * k};
    return v;
}

static float lambert_pdf(void *user, ppis_vec3 wo, ppis_vec3 wi) {
    (void)user;
    return (wo.z > 0.0f && wi.z > 0.0f) ? (float)INV_PI * wi.z : 0.0f;
}

static int32_t lambert_sample(void *user, ppis_vec3 wo, ppis_vec2 u, ppis_vec3 *wi, ppis_vec3 *value, float *pdf) {
    if (wo.z <= 0.0f) return 0;
    float r = sqrtf(u.x), phi = 2.0f * (float)PI * u.y;
    wi->x = r * cosf(phi);
    wi->y = r * sinf(phi);
    wi->z = sqrtf(fmaxf(0.0f, 1.0f - u.x));
    *value = lambert_eval(user, wo, *wi);
    *pdf = lambert_pdf(user, wo, *wi);
    return *pdf > 0.0f;
}

static ppis_vec3 to_world(const ppis_frame *f, ppis_vec3 v) {
    ppis_vec3 w = {f->s.x * v.x + f->t.x * v.y + f->n.x * v.z, f->s.y * v.x + f->t.y * v.y + f->n.y * v.z,
                   f->s.z * v.x + f->t.z * v.y + f->n.z * v.z};
    return w;
}

static ppis_vec3 to_local(const ppis_frame *f, ppis_vec3 v) {
    ppis_vec3 l = {f->s.x * v.x + f->s.y * v.y + f->s.z * v.z, f->t.x * v.x + f->t.y * v.y + f->t.z * v.z,
                   f->n.x * v.x + f->n.y * v.y + f->n.z * v.z};
    return l;
}

static double luminance(ppis_vec3 c) { return 0.212671 * c.x + 0.715160 * c.y + 0.072169 * c.z; }

static void print_sample(const char *name, int k, ppis_sample s, float pdf) {
    printf("%s %d %a %a %a %a %a\n", name, k, s.dir.x, s.dir.y, s.dir.z, s.pdf, pdf);
}

int main(void) {
    /* A library built for x86-64-v3 says which extension this CPU lacks before any other call. */
    const char *missing = ppis_missing_cpu_feature();
    if (missing) {
        fprintf(stderr, "embed: this library needs a CPU with %s\n", missing);
        return 1;
    }
    /* A 128 x 64 lat-long sky, brighter towards the zenith, with a 2 x 2 pixel sun. */
    enum { W = 128, H = 64 };
    static float latlong[W * H * 3];
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            float sky = 0.2f + 0.6f * (float)(H - j) / (float)H;
            int sun = i >= 40 && i < 42 && j >= 20 && j < 22;
            float *p = &latlong[(j * W + i) * 3];
            p[0] = sun ? 2000.0f : 0.8f * sky;
            p[1] = sun ? 2000.0f : sky;
            p[2] = sun ? 1900.0f : 1.2f * sky;
        }
    uint32_t level = ppis_equal_area_level(W, H);
    size_t texels = (size_t)1 << (2 * level);
    float *rgb = object(texels * 3 * sizeof(float), sizeof(float));
    CHECK(ppis_latlong_to_equal_area(latlong, W, H, level, 2, rgb, texels * 3));
    ppis_sanitize_rgb(rgb, texels);
    size_t pyramid_len = ppis_pyramid_len(level);
    float *pyramid = object(pyramid_len * sizeof(float), sizeof(float));
    CHECK(ppis_build_pyramid(level, rgb, texels * 3, pyramid, pyramid_len));
    ppis_env *env;
    CHECK(ppis_env_init(object(ppis_env_size(), ppis_env_align()), ppis_env_size(), level, pyramid, pyramid_len, rgb,
                        texels * 3, &env));

    /* Materials: the library's GGX conductor and the engine's own Lambertian BRDF. */
    ppis_brdf *metal, *matte;
    ppis_vec3 gold = {1.0f, 0.78f, 0.34f};
    CHECK(ppis_brdf_init_conductor(object(ppis_brdf_size(), ppis_brdf_align()), ppis_brdf_size(), 0.1f, gold, &metal));
    static lambert clay = {{0.7f, 0.5f, 0.4f}};
    /* Diffuse: its lobe is a hemisphere wide (pi/2); no cone bounds, so the two-level product
       weighs its cells by evaluating it. */
    ppis_brdf_callbacks callbacks = {&clay, lambert_eval, lambert_sample, lambert_pdf, 1, 1.5707964f, NULL};
    CHECK(ppis_brdf_init_callbacks(object(ppis_brdf_size(), ppis_brdf_align()), ppis_brdf_size(), &callbacks, &matte));

    /* Per thread: a product sampler and a two-level sampler; shared: the cones of 16 x 16 cells. */
    ppis_product *product;
    CHECK(ppis_product_init(object(ppis_product_size(), ppis_product_align()), ppis_product_size(), &product));
    ppis_two_level *two_level;
    CHECK(ppis_two_level_init(object(ppis_two_level_size(), ppis_two_level_align()), ppis_two_level_size(), &two_level));
    ppis_cones *cones;
    CHECK(ppis_cones_init(object(ppis_cones_size(4), ppis_cones_align()), ppis_cones_size(4), 4, &cones));

    /* One shading point. */
    ppis_vec3 normal = {0.6f, 0.0f, 0.8f}, wo = {0.0f, 0.6f, 0.8f};
    ppis_frame frame = ppis_frame_from_normal(normal);
    ppis_product_params params = ppis_product_params_for_mis(256);
    CHECK(ppis_product_build(product, env, metal, &frame, wo, &params, 42));
    CHECK(ppis_two_level_build(two_level, env, cones, matte, &frame, wo));

    double u[2 * 8];
    CHECK(ppis_sobol02(7, 0, 8, u));
    ppis_sample s[8];
    CHECK(ppis_product_sample_many(product, u, 8, s));
    for (int k = 0; k < 8; k++) print_sample("product", k, s[k], ppis_product_pdf(product, s[k].dir));
    for (int k = 0; k < 8; k++) {
        CHECK(ppis_two_level_sample(two_level, u[2 * k], u[2 * k + 1], &s[k]));
        print_sample("two-level", k, s[k], ppis_two_level_pdf(two_level, s[k].dir));
    }
    for (int k = 0; k < 8; k++) {
        CHECK(ppis_env_sample(env, u[2 * k], u[2 * k + 1], &s[k]));
        print_sample("env", k, s[k], ppis_env_pdf(env, s[k].dir));
    }

    /* Product-MIS with BRDF sampling, balance heuristic: 64 independent builds of 256 pairs. */
    enum { BUILDS = 64, PAIRS = 256 };
    double means[BUILDS], mean = 0.0;
    ppis_vec3 wo_local = to_local(&frame, wo);
    for (int b = 0; b < BUILDS; b++) {
        static double up[2 * PAIRS], ub[2 * PAIRS];
        CHECK(ppis_product_build(product, env, metal, &frame, wo, &params, (uint64_t)b));
        CHECK(ppis_sobol02(1000 + (uint64_t)b, 0, PAIRS, up));
        CHECK(ppis_sobol02(2000 + (uint64_t)b, 0, PAIRS, ub));
        double sum = 0.0;
        for (int k = 0; k < PAIRS; k++) {
            ppis_sample d;
            if (ppis_product_sample(product, up[2 * k], up[2 * k + 1], &d) == PPIS_OK) {
                ppis_vec3 wi = to_local(&frame, d.dir);
                double p = d.pdf + ppis_brdf_pdf(metal, wo_local, wi);
                ppis_vec3 f = ppis_brdf_eval(metal, wo_local, wi), l = ppis_env_radiance_at(env, d.uv);
                ppis_vec3 fl = {f.x * l.x, f.y * l.y, f.z * l.z};
                sum += luminance(fl) / p;
            }
            ppis_vec2 v = {(float)ub[2 * k], (float)ub[2 * k + 1]};
            ppis_vec3 wi, value;
            float pb;
            if (ppis_brdf_sample(metal, wo_local, v, &wi, &value, &pb) == PPIS_OK) {
                ppis_vec3 dir = to_world(&frame, wi), l = ppis_env_radiance(env, dir);
                ppis_vec3 fl = {value.x * l.x, value.y * l.y, value.z * l.z};
                sum += luminance(fl) / (pb + ppis_product_pdf(product, dir));
            }
        }
        means[b] = sum / PAIRS;
        mean += means[b] / BUILDS;
    }
    double var = 0.0;
    for (int b = 0; b < BUILDS; b++) var += (means[b] - mean) * (means[b] - mean) / (BUILDS - 1);
    double se = sqrt(var / BUILDS);

    /* Quadrature: every texel of the square, 8 x 8 points each (texels subtend equal solid angles). */
    int n = 1 << level, m = 8;
    double quad = 0.0;
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            ppis_vec2 centre = {((float)x + 0.5f) / (float)n, ((float)y + 0.5f) / (float)n};
            ppis_vec3 lrgb = ppis_env_radiance_at(env, centre);
            double acc = 0.0;
            for (int j = 0; j < m; j++)
                for (int i = 0; i < m; i++) {
                    ppis_vec2 p = {((float)x + ((float)i + 0.5f) / (float)m) / (float)n,
                                   ((float)y + ((float)j + 0.5f) / (float)m) / (float)n};
                    ppis_vec3 f = ppis_brdf_eval(metal, wo_local, to_local(&frame, ppis_square_to_sphere(p)));
                    ppis_vec3 fl = {f.x * lrgb.x, f.y * lrgb.y, f.z * lrgb.z};
                    acc += luminance(fl);
                }
            quad += acc * 4.0 * PI / ((double)n * n * m * m);
        }
    int pass = fabs(mean - quad) <= 3.0 * se + 2e-3 * quad;
    printf("estimate %.6f se %.6f quadrature %.6f %s\n", mean, se, quad, pass ? "PASS" : "FAIL");
    return pass ? 0 : 1;
}
