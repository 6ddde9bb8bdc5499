// The Doppler colour model (mesh4d/doppler_colour.h) against closed forms computed here: D = 1
// returns the base colour, a band shifted by the ratio of two band centres lands on the other
// band's centre with the D^3 searchlight factor, the band-integrated brightness scales as D^4
// (integrated here over frequency), the tone map's stated effect; then `render --shade doppler`
// (COLOR_0 in the .glb, plain and Draco) and `raytrace --shade doppler` (an approaching object
// bluer, a receding one redder than the plain picture).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <Eigen/Dense>
#include <tiny_gltf.h>

#include "exporters/png.h"
#include "mesh4d/doppler_colour.h"
#include "run_command.h"
#include "temp_dir.h"
#include "glb_accessors.h"

using testcli::apparentRun;
using testcli::CommandResult;
namespace fs = std::filesystem;

namespace {

constexpr double kR = 610, kG = 550, kB = 465, kS = 40;
double gauss(double x) { return std::exp(-x * x / (2 * kS * kS)); }

// The overlap matrix M_kc = g(l_k - l_c), built here from the stated centres and width.
double overlap(int k, int c) {
    const double l[3] = {kR, kG, kB};
    return gauss(l[k] - l[c]);
}

}  // namespace

TEST(DopplerColour, StatedBands) {
    EXPECT_EQ(mesh4d::kBandCentreNm[0], kR);
    EXPECT_EQ(mesh4d::kBandCentreNm[1], kG);
    EXPECT_EQ(mesh4d::kBandCentreNm[2], kB);
    EXPECT_EQ(mesh4d::kBandWidthNm, kS);
}

TEST(DopplerColour, UnitFactorGivesTheBaseColour) {
    for (const std::array<double, 3>& a : {std::array<double, 3>{0.8, 0.2, 0.1}, {0, 1, 0}, {1, 1, 1}, {0, 0, 0},
                                           {0.05, 0.3, 0.9}, {1, 0, 1}}) {
        const auto c = mesh4d::dopplerChannels(a, 1.0);
        const auto t = mesh4d::dopplerColour(a, 1.0);
        for (size_t k = 0; k < 3; ++k) {
            EXPECT_NEAR(c[k], a[k], 1e-12);
            EXPECT_NEAR(t[k], a[k], 1e-12);  // within [0, 1]: the tone map leaves it
        }
    }
}

TEST(DopplerColour, BandShiftedByTheRatioOfCentresLandsOnTheOtherBand) {
    // (from band, to band, D): observed at l_to, the light left at l_to D = l_from.
    struct Case { int from, to; double d; };
    const double l[3] = {kR, kG, kB};
    for (const Case& s : {Case{0, 1, kR / kG}, Case{1, 2, kG / kB}, Case{0, 2, kR / kB}, Case{1, 0, kG / kR},
                          Case{2, 1, kB / kG}}) {
        std::array<double, 3> a{0, 0, 0};
        a[size_t(s.from)] = 1;
        const double d3 = s.d * s.d * s.d;
        // The spectrum at the target centre: exactly the source band's peak times D^3.
        EXPECT_NEAR(mesh4d::observedSpectrum(a, s.d, l[s.to]), d3, 1e-12 * d3);
        // All three samples in closed form: D^3 g(D l_k - l_from).
        double samples[3];
        for (int k = 0; k < 3; ++k) {
            samples[k] = d3 * gauss(s.d * l[k] - l[s.from]);
            EXPECT_NEAR(mesh4d::observedSpectrum(a, s.d, l[k]), samples[k], 1e-12 * d3);
        }
        // The channels unmix the samples: M c = s (checked by multiplying, not by inverting).
        const auto c = mesh4d::dopplerChannels(a, s.d);
        for (int k = 0; k < 3; ++k) {
            double mc = 0;
            for (int j = 0; j < 3; ++j) mc += overlap(k, j) * c[size_t(j)];
            EXPECT_NEAR(mc, samples[k], 1e-12 * d3) << s.from << "->" << s.to;
        }
        // The target channel is the strongest: the colour moved into the other band.
        const auto t = mesh4d::dopplerColour(a, s.d);
        for (int k = 0; k < 3; ++k) {
            if (k != s.to) {
                EXPECT_GT(t[size_t(s.to)], t[size_t(k)]) << s.from << "->" << s.to;
            }
        }
    }
}

TEST(DopplerColour, BrightnessScalesAsD3PerSampleAndD4Integrated) {
    const std::array<double, 3> a{0.7, 0.4, 0.2};
    auto emitted = [&](double l) { return a[0] * gauss(l - kR) + a[1] * gauss(l - kG) + a[2] * gauss(l - kB); };
    // Integral over frequency nu = 1 / l (any unit; d nu = dl / l^2), Simpson's rule on l.
    auto integral = [&](auto f) {
        const double lo = 20, hi = 20000;
        const int n = 400000;
        const double h = (hi - lo) / n;
        double s = 0;
        for (int i = 0; i <= n; ++i) {
            const double l = lo + h * i;
            const double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
            s += w * f(l) / (l * l);
        }
        return s * h / 3;
    };
    const double base = integral(emitted);
    for (double d : {0.3, 0.6, 1.0, 1.7, 3.0}) {
        // Per sample: I_obs(l / D) = D^3 I_emit(l).
        for (double l : {500.0, 580.0, 640.0})
            EXPECT_NEAR(mesh4d::observedSpectrum(a, d, l / d), d * d * d * emitted(l), 1e-12 * d * d * d);
        const double obs = integral([&](double l) { return mesh4d::observedSpectrum(a, d, l); });
        EXPECT_NEAR(obs / base, std::pow(d, 4), 1e-6 * std::pow(d, 4)) << "D " << d;
    }
}

TEST(DopplerColour, ToneMapKeepsHueAndUnitRange) {
    const auto in = mesh4d::toneMap({0.2, 0.5, 1.0});
    EXPECT_EQ(in, (std::array<double, 3>{0.2, 0.5, 1.0}));
    const auto over = mesh4d::toneMap({4.0, 2.0, -0.5});
    EXPECT_DOUBLE_EQ(over[0], 1.0);
    EXPECT_DOUBLE_EQ(over[1], 0.5);
    EXPECT_DOUBLE_EQ(over[2], 0.0);
    EXPECT_EQ(mesh4d::dopplerColour({1, 1, 1}, 0.0), (std::array<double, 3>{0, 0, 0}));
    EXPECT_EQ(mesh4d::dopplerColour({1, 1, 1}, NAN), (std::array<double, 3>{0, 0, 0}));
    // Dimming below D = 1 shows: a red shift of a grey far enough leaves it darker in every channel.
    const auto dim = mesh4d::dopplerColour({0.5, 0.5, 0.5}, 0.5);
    for (double v : dim) EXPECT_LT(v, 0.5);
}

namespace {

// A(D) = D^3 M^-1 G(D), G_kc = g(l_k D - l_c), built here from the stated bands (Eigen's inverse).
Eigen::Matrix3d shiftMatrix(double d) {
    const double l[3] = {kR, kG, kB};
    Eigen::Matrix3d m, g;
    for (int k = 0; k < 3; ++k)
        for (int c = 0; c < 3; ++c) {
            m(k, c) = gauss(l[k] - l[c]);
            g(k, c) = gauss(l[k] * d - l[c]);
        }
    return d * d * d * m.inverse() * g;
}

// The tone map as docs/DOPPLER.md states it.
Eigen::Vector3d toned(Eigen::Vector3d c) {
    c = c.cwiseMax(0.0);
    return c.maxCoeff() > 1 ? Eigen::Vector3d(c / c.maxCoeff()) : c;
}

}  // namespace

TEST(DopplerColour, TheShiftIsTheMatrixA) {
    for (double d : {0.25, 0.6, 0.9, 1.0, 1.1, 1.5, 2.3, 4.4}) {
        const Eigen::Matrix3d want = shiftMatrix(d);
        const auto a = mesh4d::dopplerMatrix(d);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) EXPECT_NEAR(a[size_t(i)][size_t(j)], want(i, j), 1e-12 * (1 + want.norm())) << d;
        // dopplerChannels is A(D) a for any a (linear).
        for (const Eigen::Vector3d& c : {Eigen::Vector3d(0.8, 0.2, 0.1), Eigen::Vector3d(0.05, 0.7, 1.0)}) {
            const auto got = mesh4d::dopplerChannels({c[0], c[1], c[2]}, d);
            const Eigen::Vector3d ac = want * c;
            for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[size_t(i)], ac[i], 1e-12 * (1 + ac.norm())) << d;
        }
        // The modulation is the shaded colour of white.
        const Eigen::Vector3d w = toned(want * Eigen::Vector3d::Ones());
        const auto mod = mesh4d::dopplerModulation(d);
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(mod[size_t(i)], w[i], 1e-12) << d;
    }
    for (const double w : mesh4d::dopplerModulation(1.0)) EXPECT_NEAR(w, 1.0, 1e-14);  // A(1) = I
    EXPECT_EQ(mesh4d::dopplerMatrix(0.0)[0][0], 0.0);
}

// The modulation W(D) a against the exact toneMap(A(D) a), as doppler_colour.h states it: exact for
// a grey while white does not saturate, E max(1/m, g) for a grey when it does, and within
// |sum_{j != i} A_ij (a_j - a_i)| per channel for any colour where neither saturates.
TEST(DopplerColour, ModulationAgainstTheExactShift) {
    size_t greys = 0, saturated_greys = 0, colours = 0, mixed = 0;
    for (int n = 0; n <= 80; ++n) {
        const double d = 0.3 * std::pow(4.4 / 0.3, n / 80.0);  // 0.3 to 4.4, 0.9c's range of D
        const Eigen::Matrix3d a = shiftMatrix(d);
        const Eigen::Vector3d w = a * Eigen::Vector3d::Ones();
        const double m = w.maxCoeff();
        const auto mod = mesh4d::dopplerModulation(d);
        for (int g10 = 0; g10 <= 10; ++g10) {
            const double g = g10 / 10.0;
            const auto exact = mesh4d::dopplerColour({g, g, g}, d);
            for (size_t i = 0; i < 3; ++i) {
                const double p = mod[i] * g;
                const double want = m <= 1 ? exact[i] : exact[i] * std::max(1 / m, g);
                EXPECT_NEAR(p, want, 1e-12) << "D " << d << " grey " << g << " channel " << i;
            }
            ++(m <= 1 ? greys : saturated_greys);
        }
        for (int r = 0; r <= 5; ++r)
            for (int gg = 0; gg <= 5; ++gg)
                for (int b = 0; b <= 5; ++b) {
                    const Eigen::Vector3d c(r / 5.0, gg / 5.0, b / 5.0);
                    const Eigen::Vector3d ac = a * c;
                    if (m > 1 || ac.maxCoeff() > 1) continue;
                    const auto exact = mesh4d::dopplerColour({c[0], c[1], c[2]}, d);
                    for (int i = 0; i < 3; ++i) {
                        double bound = 0;
                        for (int j = 0; j < 3; ++j)
                            if (j != i) bound += a(i, j) * (c[j] - c[i]);
                        const double err = std::fabs(mod[size_t(i)] * c[i] - exact[size_t(i)]);
                        EXPECT_LE(err, std::fabs(bound) + 1e-12) << "D " << d << " colour " << c.transpose();
                        if (err > 0.01) ++mixed;
                    }
                    ++colours;
                }
    }
    // Every case met, and the bound is not idle: some colours do differ.
    EXPECT_GT(greys, 0u);
    EXPECT_GT(saturated_greys, 0u);
    EXPECT_GT(colours, 0u);
    EXPECT_GT(mixed, 0u);
}

namespace {

fs::path freshDir(const std::string& name) {
    const fs::path dir = testio::tempPath() / ("apparent_dcolour_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::copy_file(testcli::source("data/meshes/box.obj"), dir / "box.obj");
    return dir;
}

using testglb::floats;

}  // namespace

TEST(DopplerColour, RenderBakesColor0FromEachVertexDoppler) {
    const fs::path dir = freshDir("glb");
    std::ofstream(dir / "scene.json") << R"({ "frames": { "start": 0, "end": 0.2, "fps": 10 }, "tolerance": "vertex",
        "objects": [ { "mesh": "box.obj", "position": [-2, 0, -5], "velocity": [0.8, 0, 0] },
                     { "mesh": "box.obj", "position": [2, 0, -8], "velocity": [0, 0, 0.6] } ] })";
    for (const char* model_name : {"relativistic", "instant"}) {
        const fs::path out = dir / model_name;
        const CommandResult r = apparentRun({"render", (dir / "scene.json").string(), "--out", out.string(), "--model",
                                             model_name, "--shade", "doppler", "--attributes", "doppler", "--quiet"});
        ASSERT_EQ(r.code, 0) << r.err;
        tinygltf::TinyGLTF loader;
        tinygltf::Model model;
        std::string err, warn;
        ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, (out / (std::string(model_name) + ".glb")).string()))
            << err;
        size_t checked = 0, shifted = 0;
        for (const tinygltf::Mesh& mesh : model.meshes)
            for (const tinygltf::Primitive& prim : mesh.primitives) {
                ASSERT_TRUE(prim.attributes.count("COLOR_0") && prim.attributes.count("_DOPPLER"));
                const tinygltf::Material& mat = model.materials[size_t(prim.material)];
                for (int c = 0; c < 3; ++c) EXPECT_EQ(mat.pbrMetallicRoughness.baseColorFactor[size_t(c)], 1.0);
                ASSERT_TRUE(mat.extras.Has("base_color"));
                std::array<double, 3> base{};
                for (int c = 0; c < 3; ++c) base[size_t(c)] = mat.extras.Get("base_color").Get(c).GetNumberAsDouble();
                const auto col = floats(model, prim.attributes.at("COLOR_0"), 3);
                const auto dop = floats(model, prim.attributes.at("_DOPPLER"), 1);
                ASSERT_EQ(col.size(), 3 * dop.size());
                for (size_t i = 0; i < dop.size(); ++i) {
                    const auto want = std::string(model_name) == "instant" ? base : mesh4d::dopplerColour(base, dop[i]);
                    for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(col[3 * i + c], want[c], 2e-5);
                    if (std::fabs(col[3 * i] - base[0]) > 0.05) ++shifted;
                    ++checked;
                }
            }
        EXPECT_GT(checked, 0u);
        if (std::string(model_name) == "relativistic") EXPECT_GT(shifted, 0u);
        else EXPECT_EQ(shifted, 0u);
    }
    CommandResult r = apparentRun({"render", (dir / "scene.json").string(), "--out", (dir / "draco").string(),
                                   "--compress", "draco", "--shade", "doppler", "--quiet"});
    ASSERT_EQ(r.code, 0) << r.err;
    std::ifstream in(dir / "draco/relativistic.glb", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(bytes.find(R"("COLOR_0")"), std::string::npos);
    // meshopt: COLOR_0 as normalized uint16 in the vertex record (decoded against the plain file
    // by tests/web/meshopt_roundtrip.js).
    r = apparentRun({"render", (dir / "scene.json").string(), "--out", (dir / "m").string(), "--compress", "meshopt",
                     "--shade", "doppler", "--quiet"});
    ASSERT_EQ(r.code, 0) << r.err;
    std::ifstream mesh_in(dir / "m/relativistic.glb", std::ios::binary);
    const std::string mesh_bytes((std::istreambuf_iterator<char>(mesh_in)), std::istreambuf_iterator<char>());
    EXPECT_NE(mesh_bytes.find(R"("COLOR_0")"), std::string::npos);
    r = apparentRun({"render", (dir / "scene.json").string(), "--out", (dir / "p").string(), "--format", "ply",
                     "--shade", "doppler"});
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--shade doppler: colours go into the .glb only"), std::string::npos) << r.err;
    r = apparentRun({"render", (dir / "scene.json").string(), "--out", (dir / "x").string(), "--shade", "sepia"});
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--shade: unknown shading 'sepia'"), std::string::npos) << r.err;
    fs::remove_all(dir);
}

TEST(DopplerColour, RaytraceShiftsApproachingBlueAndRecedingRed) {
    // One orange box on the line of sight, approaching or receding at 0.3c: the centre pixel's
    // blue-to-red ratio rises (D = sqrt(1.3/0.7) > 1) or falls (D < 1) against the plain picture.
    auto centre = [](const fs::path& png) {
        apparent::RgbImage img;
        std::string error;
        EXPECT_TRUE(apparent::readPng(png.string(), &img, &error)) << error;
        const uint8_t* p = img.pixel(16, 9);
        return std::array<double, 3>{double(p[0]), double(p[1]), double(p[2])};
    };
    for (const double vz : {0.3, -0.3}) {
        const fs::path dir = freshDir(vz > 0 ? "approach" : "recede");
        std::ofstream(dir / "scene.json") << R"({ "frames": { "start": 0, "end": 0.1, "fps": 10 }, "model": "relativistic",
            "objects": [ { "mesh": "box.obj", "position": [0, 0, -10], "velocity": [0, 0, )" << vz << "] } ] }";
        std::array<std::array<double, 3>, 2> px{};
        for (int shade = 0; shade < 2; ++shade) {
            const fs::path out = dir / (shade ? "doppler" : "plain");
            const CommandResult r = apparentRun({"raytrace", (dir / "scene.json").string(), "--out", out.string(), "--size",
                                                 "32x18", "--shade", shade ? "doppler" : "plain", "--quiet"});
            ASSERT_EQ(r.code, 0) << r.err;
            px[size_t(shade)] = centre(out / "relativistic/frame_00000.png");
        }
        const double plain = (px[0][2] + 1) / (px[0][0] + 1), doppler = (px[1][2] + 1) / (px[1][0] + 1);
        if (vz > 0) EXPECT_GT(doppler, 2 * plain) << "approaching";
        else EXPECT_LT(doppler, 0.5 * plain) << "receding";
        fs::remove_all(dir);
    }
}

// figure --shade doppler: the relativistic row changes colour against --shade plain, the
// contracted row (no light travel: D = 1) keeps every pixel.
TEST(DopplerColour, FigureShadesItsRelativisticRowOnly) {
    const fs::path dir = freshDir("figure");
    std::ofstream(dir / "scene.json") << R"({ "frames": { "start": 0, "end": 0.1, "fps": 10 }, "model": "relativistic",
        "objects": [ { "mesh": "box.obj", "position": [0, 0, -4], "velocity": [0, 0, -0.3] } ] })";
    apparent::RgbImage img[2];
    for (int shade = 0; shade < 2; ++shade) {
        const fs::path out = dir / (shade ? "doppler.png" : "plain.png");
        const CommandResult r =
            apparentRun({"figure", (dir / "scene.json").string(), "--out", out.string(), "--models", "relativistic,contracted",
                         "--columns", "1", "--no-labels", "--size", "64x36", "--shade", shade ? "doppler" : "plain", "--quiet"});
        ASSERT_EQ(r.code, 0) << r.err;
        std::string error;
        ASSERT_TRUE(apparent::readPng(out.string(), &img[shade], &error)) << error;
    }
    ASSERT_EQ(img[0].rgb.size(), img[1].rgb.size());
    size_t differ[2] = {0, 0};  // top half (relativistic row), bottom half (contracted row)
    for (int y = 0; y < img[0].height; ++y)
        for (int x = 0; x < img[0].width; ++x)
            if (std::memcmp(img[0].pixel(x, y), img[1].pixel(x, y), 3) != 0) ++differ[y < img[0].height / 2 ? 0 : 1];
    EXPECT_GT(differ[0], 20u);
    EXPECT_EQ(differ[1], 0u);
    fs::remove_all(dir);
}
