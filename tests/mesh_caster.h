// A plain 3D ray caster over triangles with object ids, the tests' independent view of a cut's
// apparent meshes (the cross-checks of the 4D raytracer): the triangles are binned by their
// screen-space bounding boxes into 8 x 8 pixel tiles, then every pixel ray is tested (Moeller-
// Trumbore) against its tile's triangles; the nearest hit wins.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "mesh4d/event.h"
#include "mesh4d/slice.h"
#include "pipeline/input/scene.h"
#include "pipeline/trace/raytrace.h"

namespace testcast {

using apparent::CameraSpec;
using mesh4d::Vec3;

class MeshCaster {
public:
    MeshCaster(const CameraSpec& cam, int width, int height) : cam_(cam), w_(width), h_(height) {
        const Vec3 f0 = cam.look_at - cam.position;
        f_ = f0 / mesh4d::norm(f0);
        const Vec3 r0 = mesh4d::cross(f_, cam.up);
        r_ = r0 / mesh4d::norm(r0);
        u_ = mesh4d::cross(r_, f_);
        half_h_ = std::tan(cam.fov_deg * 3.14159265358979323846 / 360);
        half_w_ = half_h_ * width / height;
        tiles_x_ = (w_ + 7) / 8;
        tiles_y_ = (h_ + 7) / 8;
        tiles_.assign(size_t(tiles_x_ * tiles_y_), {});
    }

    void add(const Vec3& a, const Vec3& b, const Vec3& c, int32_t id) {
        const size_t index = tris_.size();
        tris_.push_back({a, b, c, id});
        // Screen bounds; a triangle reaching behind the camera covers every tile.
        double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
        bool behind = false;
        for (const Vec3& p : {a, b, c}) {
            const Vec3 d = p - cam_.position;
            const double z = mesh4d::dot(d, f_);
            if (!(z > 1e-9)) { behind = true; break; }
            const double sx = (mesh4d::dot(d, r_) / z / half_w_ + 1) * 0.5 * w_;
            const double sy = (1 - mesh4d::dot(d, u_) / z / half_h_) * 0.5 * h_;
            x0 = std::min(x0, sx); x1 = std::max(x1, sx); y0 = std::min(y0, sy); y1 = std::max(y1, sy);
        }
        int tx0 = 0, tx1 = tiles_x_ - 1, ty0 = 0, ty1 = tiles_y_ - 1;
        if (!behind) {
            tx0 = std::max(0, int(std::floor(x0 - 1)) / 8); tx1 = std::min(tiles_x_ - 1, int(std::floor(x1 + 1)) / 8);
            ty0 = std::max(0, int(std::floor(y0 - 1)) / 8); ty1 = std::min(tiles_y_ - 1, int(std::floor(y1 + 1)) / 8);
            if (x1 < -1 || y1 < -1) return;
        }
        for (int ty = ty0; ty <= ty1; ++ty)
            for (int tx = tx0; tx <= tx1; ++tx) tiles_[size_t(ty * tiles_x_ + tx)].push_back(index);
    }

    int32_t cast(int px, int py) const {
        const Vec3 d = apparent::pixelDirection(cam_, w_, h_, px, py);
        double best = INFINITY;
        int32_t id = -1;
        for (size_t i : tiles_[size_t((py / 8) * tiles_x_ + px / 8)]) {
            const Tri& t = tris_[i];
            const Vec3 e1 = t.b - t.a, e2 = t.c - t.a;
            const Vec3 p = mesh4d::cross(d, e2);
            const double det = mesh4d::dot(e1, p);
            if (det == 0) continue;
            const Vec3 s = cam_.position - t.a;
            const double bu = mesh4d::dot(s, p) / det;
            if (bu < 0 || bu > 1) continue;
            const Vec3 q = mesh4d::cross(s, e1);
            const double bv = mesh4d::dot(d, q) / det;
            if (bv < 0 || bu + bv > 1) continue;
            const double dist = mesh4d::dot(e2, q) / det;
            if (dist > 0 && dist < best) { best = dist; id = t.id; }
        }
        return id;
    }

private:
    struct Tri {
        Vec3 a, b, c;
        int32_t id;
    };
    CameraSpec cam_;
    int w_, h_;
    Vec3 f_, r_, u_;
    double half_w_ = 1, half_h_ = 1;
    int tiles_x_ = 1, tiles_y_ = 1;
    std::vector<Tri> tris_;
    std::vector<std::vector<size_t>> tiles_;
};

// A cut's apparent mesh cast as one object, id 0: the object id per pixel, row by row (-1 where
// nothing is hit).
inline std::vector<int32_t> castCut(const CameraSpec& cam, int w, int h, const mesh4d::ApparentMesh& cut) {
    MeshCaster caster(cam, w, h);
    for (const auto& t : cut.triangles)
        caster.add(cut.absolutePosition(t[0]), cut.absolutePosition(t[1]), cut.absolutePosition(t[2]), 0);
    std::vector<int32_t> image(size_t(w) * size_t(h));
    for (int py = 0; py < h; ++py)
        for (int px = 0; px < w; ++px) image[size_t(py * w + px)] = caster.cast(px, py);
    return image;
}

// Two object-id pictures of one size compared: `shown` pixels show an object in either, `differ`
// show different ones, and `far` of those have neither picture's object within one pixel in the
// other picture (a difference of more than an edge's rasterization).
struct ImageDifference {
    long long shown = 0, differ = 0, far = 0;
};
inline ImageDifference compareObjectImages(const std::vector<int32_t>& a, const std::vector<int32_t>& b, int w, int h) {
    auto near = [&](const std::vector<int32_t>& image, int px, int py, int32_t value) {
        for (int y = std::max(0, py - 1); y <= std::min(h - 1, py + 1); ++y)
            for (int x = std::max(0, px - 1); x <= std::min(w - 1, px + 1); ++x)
                if (image[size_t(y * w + x)] == value) return true;
        return false;
    };
    ImageDifference d;
    for (int py = 0; py < h; ++py)
        for (int px = 0; px < w; ++px) {
            const int32_t va = a[size_t(py * w + px)], vb = b[size_t(py * w + px)];
            if (va < 0 && vb < 0) continue;
            ++d.shown;
            if (va == vb) continue;
            ++d.differ;
            d.far += !near(b, px, py, va) || !near(a, px, py, vb);
        }
    return d;
}

}  // namespace testcast
