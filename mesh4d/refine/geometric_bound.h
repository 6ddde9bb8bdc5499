// The geometric distance between a straight output triangle and the exact apparent surface patch
// it stands for, bounded from the parametric bound (chord_error.h) and the direction of the
// motion; uniform motion, the past cone. Stated and tested (tests/geometric_bound_test.cpp); the
// refinement uses only its exact case, faces that contain the velocity (slide_bound.h), and
// bounds every other piece's parametric error (chord_error.h).
//
// Setting (chord_error.h). In the local coordinates the exact map is F(s) = s - v delta(s) over
// the shape triangle (s the shape offset, affine in the rest point), and the straight triangle T
// with exact corners is L, the linear interpolant of F. With eps = L delta - delta >= 0 (delta is
// convex) and E >= eps on the triangle (E = Q + R, chord_error.h: b E is ChordError::bound),
//     L(p) = F(p) - v eps(p),      w(p) = L(p) - F(p) = -b eps(p) u,   u = v / b,
// so the parametric error b eps is along u. The geometric distance is the distance to the nearest
// point, and a displacement along the surface costs nothing: only the part of w across the
// surface, or across the patch's rim, remains.
//
// Term 1, the derivative of the map. P = y0 + F(s) is the apparent point relative to the camera
// and |P| = D + delta(s) its light delay (lightcone.h: y0 relative to the camera, D its delay).
// Differentiating |P| along an in-plane direction a, with P^ = P / |P|:
//     P^.(a - v grad delta.a) = grad delta.a,  so  grad delta.a = P^.a / (1 + P^.v),
//     J a = a - v (P^.a) / (1 + P^.v),          J^-1 y = y + v (P^.y)     (Sherman-Morrison),
// 1 + P^.v >= 1 - b > 0: the map is regular and |J^-1 y| <= (1 + b) |y|.
// Term 2, across the surface (interior). Let n be the exact unit normal at F(p) and w_t the part
// of w in the tangent plane. Slide along the surface: Delta = J^-1 w_t (in the triangle's plane),
// F(p + Delta) = F(p) + w_t - v rho, rho = delta(p + Delta) - delta(p) - grad delta.Delta in
// [0, |Delta|^2 ||H|| / 2] (H the Hessian of delta). So, while p + Delta stays in the triangle,
//     |L(p) - F(p + Delta)| = |(w.n) n + v rho| <= b E |u.n| + b rho.
// |u.n| in closed form: with nu the unit normal of the shape triangle, a1, a2 an orthonormal basis
// of its plane and gamma = the in-plane part of P^ / (1 + P^.v) (the gradient of delta in it),
//     J a1 x J a2 = nu + (nu x gamma) x v = nu (1 - v.gamma) + gamma (v.nu),
//     u.(J a1 x J a2) = u.nu,      |u.n| = |u.nu| / sqrt((1 - v.gamma)^2 + |gamma|^2 (v.nu)^2).
// Zero on a face containing v (u.nu = 0): there the error is a slide within the face.
// Term 3, across the rim (the edges). Where the slide leaves the triangle, go to its edge, then
// slide along the edge's exact curve to cancel the part along the edge's tangent t_e: the residual
// is |w| |t_e x ((1 - tau) u + tau (u.n) n)| <= b E max(|u x t_e|, |u.n|) (tau in [0, 1] the part
// of the slide made before the edge), plus the second Taylor remainder of the slide along the
// edge. For an edge of direction d (unit, in the shape plane),
//     |u x t_e| = |u x J d| / |J d| = |u x d| / |d - v (gamma.d)|   (u x v = 0).
// Exact on the rim to first order: b eps |u x t_e| is the distance from the chord's point to the
// edge's exact curve. (Assumed: the slide along an edge does not run past its corner, where eps
// is 0; true once the bound is small against the triangle's sides.)
// Term 4, the other direction (exact -> output). F(p) = L(p) + b eps u: the same slides on the
// flat triangle T, exactly (no remainder), with T's normal nu_T and straight sides:
// b E max(|u.nu_T|, |u x side|).
// Term 5, over the patch. gamma depends on the point through P^ only: |d gamma| <= |dP^| (1 / c + b / c^2)
// (d (P^ / (1 + P^.v)) = dP^ / (1 + P^.v) - P^ (v.dP^) / (1 + P^.v)^2), c the least 1 + P^.v over
// the directions (at least the corners' least less b phi; 1 - b at worst). The directions P^ of the
// patch's points lie within phi = theta + 2 b E / P_min of a corner's (theta: the largest angle
// between two corners' directions, where the straight triangle's points look; the patch is off by
// at most b E, seen from at least P_min = min_i |P_i| - the longest side). The denominators above
// are Lipschitz in gamma with constants 2 b (the normal's) and b (the edge's), so
//     |u.n| <= |u.nu| / (min_corners sqrt(...) - 2 b phi (1 / c + b / c^2)),
//     |u x t_e| <= |u x d| / (min_ends |d - v (gamma.d)| - b phi (1 / c + b / c^2)),
// each taken as 1 when the denominator is not positive (|u.n|, |u x t| <= 1 always).
// Term 6, the second order. ||H|| <= 1 / ((1 - b^2) m), m a lower bound of |x|_M on the slid
// region (chord_error.h; |.|_M <= |.|), here m = min_i |x_i|_M - the longest side - 3 b E. The
// two slides have |Delta| <= (1 + b) |residual| <= (1 + b) 1.05 b E (while rho <= 0.05 E, checked),
// so the two remainders together are at most
//     K = b (1 + b)^2 (1.05 b E)^2 / ((1 - b^2) m).
// The bound. With G = the largest of the factors above (patch normal and edges, T's normal and
// sides),
//     geometric distance(T, patch) <= min(b E, b E G + K).
// b E G is first order in the parametric bound; K second order (the parametric bound squared over
// the distance: about b E times (b E / |x|) / (1 - b)). Exact where it can be: 0 inside a face
// that contains v, the rim's first-order distance on its edges. For a triangle standing alone every
// edge is rim (each edge is where one of the two directions' slides leaves it), so G is at least
// the largest |u x side|, and the standalone bound is below the parametric one only by that sine;
// within a surface, an edge shared with a triangle whose patch continues the surface smoothly
// (the same rest plane) is no rim: the slide continues into the neighbour, and the interior term
// alone remains (GeometricBound::interior) where the neighbours' terms hold too.
#pragma once

#include <algorithm>
#include <cmath>

#include "chord_error.h"

namespace mesh4d {

struct GeometricBound {
    double bound = 0;       // min(b E, b E G + K): the two-sided geometric distance, standalone triangle
    double interior = 0;    // b E max(|u.n|, |u.nu_T|) + K: the part across the surface
    double edge[3] = {0, 0, 0};  // b E |u x t_e| + K per side (corners e, e + 1): the rim's part
    double second_order = 0;     // K
};

// The bound for the triangle with exact corner events `corner` (local coordinates, as chordError)
// whose parametric bound is `parametric` (b E: ChordError::bound), seen through the past cone
// anchored at `anchor`.
inline GeometricBound geometricBound(const ViewAnchor& anchor, const Motion& m, const Event corner[3], double parametric) {
    GeometricBound r;
    const double b = m.beta;
    if (b == 0 || parametric == 0) return r;
    r.bound = parametric;
    if (!(parametric < INFINITY)) return r;
    const Vec3 u = m.velocity / b;
    // Step: the corners' shape offsets s, directions from the camera P^, and the triangle's frame.
    Vec3 s[3], P[3], dir[3];
    double Pmin = INFINITY, side = 0, xm_min = INFINITY;
    for (int i = 0; i < 3; ++i) {
        s[i] = shapeOfEvent(m, corner[i]);
        P[i] = anchor.y0 + corner[i].x;
        dir[i] = P[i] / norm(P[i]);
        Pmin = std::min(Pmin, norm(P[i]));
        xm_min = std::min(xm_min, normMOfEvent(anchor, m, corner[i]));
    }
    for (int i = 0; i < 3; ++i) side = std::max(side, norm(s[(i + 1) % 3] - s[i]));
    Vec3 nu = cross(s[1] - s[0], s[2] - s[0]);
    if (!(norm(nu) > 0)) return r;
    nu = nu / norm(nu);
    // The in-plane gradient of delta at each corner: gamma = (P^ - (P^.nu) nu) / (1 + P^.v).
    Vec3 gamma[3];
    for (int i = 0; i < 3; ++i) gamma[i] = (dir[i] - nu * dot(dir[i], nu)) / (1 + dot(dir[i], m.velocity));
    // Step: phi, the angular reach of the patch's directions from a corner's, and the Lipschitz shift of gamma.
    double theta = 0;
    for (int i = 0; i < 3; ++i) theta = std::max(theta, std::acos(std::clamp(dot(dir[i], dir[(i + 1) % 3]), -1.0, 1.0)));
    const double Plow = Pmin - side;
    if (!(Plow > 0)) return r;
    const double phi = theta + 2 * parametric / Plow;
    // |d gamma| <= |dP^| (1 / c + b / c^2) with c the least 1 + P^.v over the directions.
    double c = INFINITY;
    for (int i = 0; i < 3; ++i) c = std::min(c, 1 + dot(dir[i], m.velocity));
    c -= b * phi;
    if (!(c > 0)) return r;
    const double shift = phi * (1 / c + b / (c * c));  // bound of |gamma(p) - gamma(corner)|
    // Step: the patch's normal factor |u.n| and T's |u.nu_T| (T's plane is the corners' apparent points).
    double den_n = INFINITY;
    for (int i = 0; i < 3; ++i) {
        const double vg = dot(m.velocity, gamma[i]), vn = dot(m.velocity, nu);
        den_n = std::min(den_n, std::sqrt((1 - vg) * (1 - vg) + norm2(gamma[i]) * vn * vn));
    }
    den_n -= 2 * b * shift;
    const double u_nu = std::fabs(dot(u, nu));
    const double normal_patch = u_nu == 0 ? 0.0 : (den_n > 0 ? std::min(1.0, u_nu / den_n) : 1.0);
    Vec3 nuT = cross(P[1] - P[0], P[2] - P[0]);
    const double normal_T = norm(nuT) > 0 ? std::fabs(dot(u, nuT / norm(nuT))) : 1.0;
    // Step: the edges' factors |u x t_e|, of the exact curves (from both ends) and of T's sides.
    double edge_factor[3];
    for (int e = 0; e < 3; ++e) {
        const int i = e, j = (e + 1) % 3;
        const Vec3 d = (s[j] - s[i]) / norm(s[j] - s[i]);
        const double num = norm(cross(u, d));
        const double den = std::min(norm(d - m.velocity * dot(gamma[i], d)), norm(d - m.velocity * dot(gamma[j], d))) -
                           b * shift;
        const double curve = num == 0 ? 0.0 : (den > 0 ? std::min(1.0, num / den) : 1.0);
        const Vec3 chord = P[j] - P[i];
        const double straight = norm(cross(u, chord)) / norm(chord);
        edge_factor[e] = std::max(curve, straight);
    }
    // Step: the second-order term K.
    const double m_low = xm_min - side - 3 * parametric;
    if (!(m_low > 0)) return r;
    const double H = 1 / (m.one_minus_beta2 * m_low);            // ||H|| on the slid region
    const double slide = (1 + b) * 1.05 * parametric;            // |Delta|, both slides
    if (!(0.5 * H * slide * slide <= 0.05 * parametric / b)) return r;  // rho <= 0.05 E
    const double K = b * slide * slide * H;
    r.second_order = K;
    // Step: the bound.
    const double normal = std::max(normal_patch, normal_T);
    r.interior = parametric * normal + K;
    double G = normal;
    for (int e = 0; e < 3; ++e) {
        r.edge[e] = parametric * edge_factor[e] + K;
        G = std::max(G, edge_factor[e]);
    }
    r.bound = std::min(parametric, parametric * G + K);
    return r;
}

}  // namespace mesh4d
