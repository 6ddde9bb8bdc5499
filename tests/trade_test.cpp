// `apparent trade` end to end (pipeline/commands/trade.h): the table, trade.csv and the plot files on a
// shipped trade scene; every tolerance row within its tolerance and the uniform rows' errors
// falling about fourfold per level (the chord error of a halved edge: second order); bad options
// refused with one line; the affine models said to need nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "run_command.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using testcli::apparentRun;
using testcli::source;

namespace {
std::vector<std::map<std::string, std::string>> readCsv(const fs::path& path) {
    std::ifstream f(path);
    std::string line;
    std::getline(f, line);
    std::vector<std::string> names;
    std::stringstream header(line);
    for (std::string n; std::getline(header, n, ',');) names.push_back(n);
    std::vector<std::map<std::string, std::string>> rows;
    while (std::getline(f, line)) {
        std::stringstream ss(line);
        std::map<std::string, std::string> row;
        for (size_t i = 0; i < names.size(); ++i) std::getline(ss, row[names[i]], ',');
        rows.push_back(row);
    }
    return rows;
}
}  // namespace

TEST(Trade, TableCsvAndPlotOnTheBoxScene) {
    const fs::path dir = testio::tempPath() / ("apparent_trade_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    const auto r = apparentRun({"trade", source("data/scenes/trade/box_near.json"), "--out", dir.string(), "--levels",
                                "3", "--tolerances", "1e-2,1e-3", "--quiet"});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("uniform level 3"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("geometric"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("For vertex mode's error"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("For a tenth of it"), std::string::npos) << r.out;
    const auto rows = readCsv(dir / "trade.csv");
    ASSERT_EQ(rows.size(), 1u + 3u + 2u);
    EXPECT_EQ(rows[0].at("family"), "vertex");
    double previous_uniform = std::stod(rows[0].at("error_ls"));
    for (const auto& row : rows) {
        const double error = std::stod(row.at("error_ls")), parameter = std::stod(row.at("parameter"));
        // The geometric distance (nearest points) beside the parametric one: never above it (a minimum
        // over a larger set, the same samples), and not zero on this box (its faces x = const are
        // across the velocity, where the error is not a slide).
        const double geometric = std::stod(row.at("geometric_error_ls"));
        EXPECT_LE(geometric, error * (1 + 1e-12)) << row.at("family") << " " << parameter;
        if (row.at("family") != "tolerance") {
            EXPECT_GT(geometric, 0.3 * error) << row.at("family") << " " << parameter;
        }
        EXPECT_NEAR(std::stod(row.at("geometric_error_rel")) * std::sqrt(3.0), geometric, 1e-9 * geometric);
        EXPECT_GT(std::stod(row.at("triangles_per_frame")), 0);
        EXPECT_GT(std::stod(row.at("glb_bytes_per_frame")), 0);
        if (row.at("family") == "tolerance") {  // --tolerance bounds the geometric distance (the faces y, z = const slide)
            EXPECT_LE(geometric, parameter) << "T " << parameter;
            EXPECT_GE(geometric, 0.5 * parameter) << "T " << parameter;
        }
        if (row.at("family") == "uniform") {
            EXPECT_NEAR(previous_uniform / error, 4.0, 1.0) << "level " << parameter;
            previous_uniform = error;
        }
    }
    EXPECT_TRUE(fs::exists(dir / "trade.gp"));
    EXPECT_TRUE(fs::exists(dir / "trade.dat"));
    if (std::system("command -v gnuplot >/dev/null 2>&1") == 0) {  // scripts/setup.sh installs it
        std::ifstream png(dir / "trade.png", std::ios::binary);
        char magic[8] = {};
        png.read(magic, 8);
        EXPECT_EQ(std::string(magic + 1, 3), "PNG") << "trade.png is not a PNG";
    }
    fs::remove_all(dir);
}

TEST(Trade, AffineModelsAndBadOptions) {
    const auto inst = apparentRun({"trade", source("data/scenes/trade/plate.json"), "--model", "instant", "--out",
                                   (testio::tempPath() / "apparent_trade_inst").string()});
    EXPECT_EQ(inst.code, 0);
    EXPECT_NE(inst.out.find("vertex mode is exact"), std::string::npos) << inst.out;
    const auto bad = apparentRun({"trade", source("data/scenes/trade/plate.json"), "--tolerances", "1e-3,x"});
    EXPECT_EQ(bad.code, 2);
    EXPECT_NE(bad.err.find("--tolerances: 'x'"), std::string::npos) << bad.err;
    const auto two = apparentRun({"trade", source("data/scenes/trade/plate.json"), "--model", "finite,relativistic"});
    EXPECT_EQ(two.code, 2);
    EXPECT_NE(two.err.find("one model at a time"), std::string::npos) << two.err;
    const auto help = apparentRun({"trade", "--help"});
    EXPECT_EQ(help.code, 0);
    EXPECT_NE(help.out.find("--tolerances"), std::string::npos);
}

// Motions beyond uniform: the shipped spinning wheel (rim at 0.9c, seen along its axis)
// gets all three families; every tolerance row lies within its T (measured against the exact
// surface from the true worldlines, measure.h crossingBySearch), and the error falls as T does and
// as the uniform level rises. An object that cannot take a tolerance (a spinning one that begins
// existing within the frames) is refused with one line naming its field.
TEST(Trade, SpinningWheelAllFamiliesErrorFallsWithT) {
    testcli::TempDir dir;
    const auto r = apparentRun({"trade", source("data/scenes/spinning_wheel.json"), "--out", dir.str(), "--frames", "3:4",
                                "--levels", "2", "--tolerances", "3e-2,1e-2,3e-3", "--quiet"});
    ASSERT_EQ(r.code, 0) << r.err;
    const auto rows = readCsv(dir / "trade.csv");
    ASSERT_EQ(rows.size(), 1u + 2u + 3u);
    std::map<std::string, int> count;
    double previous_uniform = INFINITY, previous_tolerance = INFINITY;
    for (const auto& row : rows) {
        ++count[row.at("family")];
        const double error = std::stod(row.at("error_ls")), parameter = std::stod(row.at("parameter"));
        // The geometric distance of a spinning body (exact points by measure.h's root search): never
        // above the parametric one.
        const double geometric = std::stod(row.at("geometric_error_ls"));
        EXPECT_LE(geometric, error * (1 + 1e-12)) << row.at("family") << " " << parameter;
        EXPECT_GT(geometric, 0) << row.at("family") << " " << parameter;
        EXPECT_GT(error, 0);
        EXPECT_EQ(row.at("skipped"), "0");
        if (row.at("family") == "uniform") {
            EXPECT_LT(error, previous_uniform) << "level " << parameter;
            previous_uniform = error;
        }
        if (row.at("family") == "tolerance") {
            EXPECT_LE(error, parameter) << "T " << parameter;
            EXPECT_LT(error, previous_tolerance) << "T " << parameter;
            previous_tolerance = error;
        }
    }
    EXPECT_EQ(count["vertex"], 1);
    EXPECT_EQ(count["uniform"], 2);
    EXPECT_EQ(count["tolerance"], 3);
    EXPECT_NE(r.out.find("T = 0.003 x size"), std::string::npos) << r.out;

    std::ifstream in(source("data/scenes/spinning_wheel.json"));
    std::stringstream text;
    text << in.rdbuf();
    std::string scene = text.str();
    scene.replace(scene.find("\"../meshes/wheel.obj\""), 21, "\"" + source("data/meshes/wheel.obj") + "\", \"exists\": [0.3, 100]");
    const fs::path path = dir / "exists.json";
    std::ofstream(path) << scene;
    const auto refused = apparentRun({"trade", path.string(), "--out", dir.str(), "--quiet"});
    EXPECT_EQ(refused.code, 2);
    EXPECT_NE(refused.err.find("exists.json: objects[0].angular_velocity: a spinning object that begins or ends existing"),
              std::string::npos)
        << refused.err;
    EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
}
