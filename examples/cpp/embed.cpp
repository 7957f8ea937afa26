// Embedding ppis in a C++17 engine: the library's objects in engine-owned, aligned storage
// (RAII), an engine material as a class whose methods become the BRDF callbacks, and the
// two-level product of one shading point in MIS with BRDF sampling, checked against
// quadrature.
//
//   cargo build --release -p sampler-capi
//   c++ -std=c++17 -O2 -Wall -Wextra -pedantic examples/cpp/embed.cpp -Isampler-capi/include
//       target/release/libsampler_capi.a -lpthread -ldl -o embed_cpp && ./embed_cpp
//
// It prints the first samples as hex floats (sampler-capi/tests/integration/examples.rs compares them bit
// for bit with the Rust API) and exits 1 when the estimate misses.
#include "ppis.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

void check(ppis_status status, const char *what) {
    if (status != PPIS_OK) throw std::runtime_error(std::string(what) + " failed (" + std::to_string(status) + ")");
}

// Storage for one library object, sized and aligned as the library asks, freed with it.
class Storage {
  public:
    Storage(std::size_t size, std::size_t align) : size_(size), align_(align), bytes_(::operator new(size, std::align_val_t(align))) {}
    ~Storage() { ::operator delete(bytes_, std::align_val_t(align_)); }
    Storage(const Storage &) = delete;
    Storage &operator=(const Storage &) = delete;
    void *data() const { return bytes_; }
    std::size_t size() const { return size_; }

  private:
    std::size_t size_, align_;
    void *bytes_;
};

// An engine's Lambertian material; its methods are the BRDF callbacks.
struct Clay {
    ppis_vec3 albedo;

    ppis_vec3 eval(ppis_vec3 wo, ppis_vec3 wi) const {
        if (wo.z <= 0.0f || wi.z <= 0.0f) return {0.0f, 0.0f, 0.0f};
        float k = static_cast<float>(M_1_PI) * wi.z;
        return {albedo.x * k, albedo.y * k, albedo.z * k};
    }
    float pdf(ppis_vec3 wo, ppis_vec3 wi) const {
        return (wo.z > 0.0f && wi.z > 0.0f) ? static_cast<float>(M_1_PI) * wi.z : 0.0f;
    }
    bool sample(ppis_vec3 wo, ppis_vec2 u, ppis_vec3 &wi, ppis_vec3 &value, float &density) const {
        if (wo.z <= 0.0f) return false;
        float r = std::sqrt(u.x), phi = 2.0f * static_cast<float>(M_PI) * u.y;
        wi = {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::fmax(0.0f, 1.0f - u.x))};
        value = eval(wo, wi);
        density = pdf(wo, wi);
        return density > 0.0f;
    }

    ppis_brdf_callbacks callbacks() {
        ppis_brdf_callbacks c{};
        c.user = this;
        c.eval = [](void *user, ppis_vec3 wo, ppis_vec3 wi) { return static_cast<Clay *>(user)->eval(wo, wi); };
        c.pdf = [](void *user, ppis_vec3 wo, ppis_vec3 wi) { return static_cast<Clay *>(user)->pdf(wo, wi); };
        c.sample = [](void *user, ppis_vec3 wo, ppis_vec2 u, ppis_vec3 *wi, ppis_vec3 *value, float *pdf) -> int32_t {
            return static_cast<Clay *>(user)->sample(wo, u, *wi, *value, *pdf) ? 1 : 0;
        };
        c.is_diffuse = 1;
        c.lobe_width = 1.5707964f;  // a hemisphere; no cone bounds: the two-level build evaluates
        return c;
    }
};

ppis_vec3 operator*(ppis_vec3 a, ppis_vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
double luminance(ppis_vec3 c) { return 0.212671 * c.x + 0.715160 * c.y + 0.072169 * c.z; }

ppis_vec3 to_local(const ppis_frame &f, ppis_vec3 v) {
    return {f.s.x * v.x + f.s.y * v.y + f.s.z * v.z, f.t.x * v.x + f.t.y * v.y + f.t.z * v.z,
            f.n.x * v.x + f.n.y * v.y + f.n.z * v.z};
}
ppis_vec3 to_world(const ppis_frame &f, ppis_vec3 v) {
    return {f.s.x * v.x + f.t.x * v.y + f.n.x * v.z, f.s.y * v.x + f.t.y * v.y + f.n.y * v.z,
            f.s.z * v.x + f.t.z * v.y + f.n.z * v.z};
}

void print(const char *name, int k, const ppis_sample &s, float pdf) {
    std::printf("%s %d %a %a %a %a %a\n", name, k, s.dir.x, s.dir.y, s.dir.z, s.pdf, pdf);
}

int run() {
    // A library built for x86-64-v3 says which extension this CPU lacks before any other call.
    if (const char *missing = ppis_missing_cpu_feature())
        throw std::runtime_error(std::string("this library needs a CPU with ") + missing);
    // The same sky as the C example: brighter towards the zenith, a 2 x 2 pixel sun.
    constexpr int W = 128, H = 64;
    std::vector<float> latlong(W * H * 3);
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            float sky = 0.2f + 0.6f * static_cast<float>(H - j) / static_cast<float>(H);
            bool sun = i >= 40 && i < 42 && j >= 20 && j < 22;
            float *p = &latlong[(j * W + i) * 3];
            p[0] = sun ? 2000.0f : 0.8f * sky;
            p[1] = sun ? 2000.0f : sky;
            p[2] = sun ? 1900.0f : 1.2f * sky;
        }
    std::uint32_t level = ppis_equal_area_level(W, H);
    std::size_t texels = std::size_t(1) << (2 * level);
    std::vector<float> rgb(texels * 3), pyramid(ppis_pyramid_len(level));
    check(ppis_latlong_to_equal_area(latlong.data(), W, H, level, 2, rgb.data(), rgb.size()), "resample");
    ppis_sanitize_rgb(rgb.data(), texels);
    check(ppis_build_pyramid(level, rgb.data(), rgb.size(), pyramid.data(), pyramid.size()), "pyramid");
    Storage env_mem(ppis_env_size(), ppis_env_align());
    ppis_env *env = nullptr;
    check(ppis_env_init(env_mem.data(), env_mem.size(), level, pyramid.data(), pyramid.size(), rgb.data(), rgb.size(), &env),
          "env");

    Clay clay{{0.7f, 0.5f, 0.4f}};
    ppis_brdf_callbacks callbacks = clay.callbacks();
    Storage brdf_mem(ppis_brdf_size(), ppis_brdf_align());
    ppis_brdf *matte = nullptr;
    check(ppis_brdf_init_callbacks(brdf_mem.data(), brdf_mem.size(), &callbacks, &matte), "brdf");
    Storage cones_mem(ppis_cones_size(4), ppis_cones_align());
    ppis_cones *cones = nullptr;
    check(ppis_cones_init(cones_mem.data(), cones_mem.size(), 4, &cones), "cones");
    Storage sampler_mem(ppis_two_level_size(), ppis_two_level_align());
    ppis_two_level *sampler = nullptr;
    check(ppis_two_level_init(sampler_mem.data(), sampler_mem.size(), &sampler), "two-level");

    const ppis_vec3 normal{0.6f, 0.0f, 0.8f}, wo{0.0f, 0.6f, 0.8f};
    const ppis_frame frame = ppis_frame_from_normal(normal);
    check(ppis_two_level_build(sampler, env, cones, matte, &frame, wo), "build");
    std::array<double, 16> u{};
    check(ppis_sobol02(7, 0, 8, u.data()), "points");
    std::array<ppis_sample, 8> s{};
    check(ppis_two_level_sample_many(sampler, u.data(), s.size(), s.data()), "sample");
    for (int k = 0; k < 8; k++) print("two-level", k, s[k], ppis_two_level_pdf(sampler, s[k].dir));

    // Two-level MIS with the material's own sampling, balance heuristic; the two-level build is
    // deterministic, so independent estimates come from independent point sets.
    constexpr int ESTIMATES = 256, PAIRS = 256;
    const ppis_vec3 wo_local = to_local(frame, wo);
    std::vector<double> up(2 * PAIRS), ub(2 * PAIRS), means;
    for (int e = 0; e < ESTIMATES; e++) {
        check(ppis_sobol02(1000 + e, 0, PAIRS, up.data()), "points");
        check(ppis_sobol02(2000 + e, 0, PAIRS, ub.data()), "points");
        double sum = 0.0;
        for (int k = 0; k < PAIRS; k++) {
            ppis_sample d{};
            if (ppis_two_level_sample(sampler, up[2 * k], up[2 * k + 1], &d) == PPIS_OK) {
                ppis_vec3 wi = to_local(frame, d.dir);
                sum += luminance(clay.eval(wo_local, wi) * ppis_env_radiance_at(env, d.uv)) / (d.pdf + clay.pdf(wo_local, wi));
            }
            ppis_vec3 wi{}, value{};
            float pb = 0.0f;
            if (clay.sample(wo_local, {static_cast<float>(ub[2 * k]), static_cast<float>(ub[2 * k + 1])}, wi, value, pb)) {
                ppis_vec3 dir = to_world(frame, wi);
                sum += luminance(value * ppis_env_radiance(env, dir)) / (pb + ppis_two_level_pdf(sampler, dir));
            }
        }
        means.push_back(sum / PAIRS);
    }
    double mean = 0.0, var = 0.0;
    for (double m : means) mean += m / ESTIMATES;
    for (double m : means) var += (m - mean) * (m - mean) / (ESTIMATES - 1);
    const double se = std::sqrt(var / ESTIMATES);

    const int n = 1 << level, m = 8;
    double quad = 0.0;
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            const ppis_vec3 l = ppis_env_radiance_at(env, {(x + 0.5f) / n, (y + 0.5f) / n});
            for (int j = 0; j < m; j++)
                for (int i = 0; i < m; i++) {
                    ppis_vec2 p{(x + (i + 0.5f) / m) / n, (y + (j + 0.5f) / m) / n};
                    quad += luminance(clay.eval(wo_local, to_local(frame, ppis_square_to_sphere(p))) * l) * 4.0 * M_PI /
                            (double(n) * n * m * m);
                }
        }
    const bool pass = std::fabs(mean - quad) <= 3.0 * se + 2e-3 * quad;
    std::printf("estimate %.6f se %.6f quadrature %.6f %s\n", mean, se, quad, pass ? "PASS" : "FAIL");
    return pass ? 0 : 1;
}

}  // namespace

int main() {
    try {
        return run();
    } catch (const std::exception &e) {
        std::fprintf(stderr, "embed: %s\n", e.what());
        return 1;
    }
}
