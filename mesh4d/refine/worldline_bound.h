// A bound on the second derivative of the apparent-point map of a motion that is not uniform
// (worldline.h: spin, rolling, Born-rigid acceleration, keyframed paths with the kinks where the
// emission time crosses a key, below), over one rest triangle: what the
// tolerance mode of these motions (worldline_refine.h) bounds its chords by.
//
// The map. Rest point q's worldline is the event E(s, q) = (t(s, q), x(s, q)) at the object's
// time s; at a fixed s it is affine in q for every motion of worldline.h (a spin turns the rest
// mesh, an acceleration moves it Born-rigidly, a boost or the Galilean carry is affine), so
// t_qq = 0 and x_qq = 0. The apparent point is F(q) = x(sigma(q), q), sigma(q) the root of
//     g(s, q) = t_c - t(s, q) - rho(s, q) = 0,   rho = |x - C|   (past cone; on a hyperplane g = t_c - t).
// Along a line of rest points q(l) = q0 + l u (derivatives in l written with dots, primes on sigma):
//     sigma' = -(t_q u + n.x_q u) / Lambda,   Lambda = t_s + n.x_s   (n = (x - C) / rho; t_s on a hyperplane)
//     x.     = x_s sigma' + x_q u
//     Lambda sigma'' = -[(t_ss + n.x_ss) sigma'^2 + 2 (t_sq + n.x_sq)[u] sigma' + P / rho],  P = |x._perp|^2 <= |x.|^2
//     x..    = x_s sigma'' + x_ss sigma'^2 + 2 x_sq[u] sigma'
//     t..    = t_s sigma'' + t_ss sigma'^2 + 2 t_sq[u] sigma'
// (differentiate g(sigma(q(l)), q(l)) = 0 twice; rho.. = n.x.. + P / rho). Lambda > 0 is the
// Doppler denominator dt/ds (1 - n.V) of the point: it is what makes the map steep when a part
// moves toward the camera, and it is the term a tight bound must not take at its worst case.
//
// The bound, term by term, over the triangle (q in it, s = sigma(q)):
//   - rates of the worldline, as (time part, space part) magnitudes in the object's own frame (the
//     centre frame of a spin, the start frame of an acceleration; the lab for the Galilean carry),
//     per unit |u| where q enters (FrameRates, worldline_bound.cpp):
//       spin:   (T, Y)_s = (1, w x Y), |w x Y| <= c = max_i |w x q_i| (the rim speed of the
//               farthest corner from the axis: a distance to a line is convex), (T, Y)_ss =
//               (0, w x (w x Y)) <= (0, |w| c), (T, Y)_q = (0, R u) <= (0, 1), (T, Y)_sq =
//               (0, w x R u) <= (0, |w|)   (the curvature |w|^2 rho and the spread of the
//               velocity across the triangle, |w| l, of the brief);
//               Galilean carry: (1, w x Y + v) <= (1, max_i maxGalileanSpeed(q_i)), the rest as above;
//       Born-rigid acceleration (relativistic on the cone: the closed forms of "A Born-rigid
//               acceleration on the cone" below instead) (xi = 1/|a| + q.k in [xi_lo, xi_hi] from
//               the corners, s in a window
//               [s_lo, s_hi], S = max(s_hi, 0), ch = cosh(|a| S), sh = sinh(|a| S)):
//               (T, Y)_s = xi |a| (cosh, k sinh) <= xi_hi |a| (ch, sh), (T, Y)_ss = xi |a|^2 (sinh,
//               k cosh) <= xi_hi |a|^2 (sh, ch) (the proper acceleration 1/xi), (T, Y)_q = ((k.u)
//               sinh, u + k (k.u)(cosh - 1)) <= (sh, ch), (T, Y)_sq = (k.u)|a| (cosh, k sinh) <=
//               |a| (ch, sh); before t0 (s <= 0) the uniform (1, 0), (0, 0), (0, 1), (0, 0); a window
//               across s = 0 takes the larger of both (the map is C1 and piecewise C2 there, which is
//               all the Taylor remainder below needs);
//               Galilean carry (x = X0 + q + P(s), s the lab time since t0): (1, |P'|) with |P'| <=
//               (b + th) / (1 + b th), th = tanh(|a| tau(S)) (velocity addition at its worst
//               angle), (0, |P''|) <= (0, |a|) (a lab 3-acceleration is at most the proper one
//               over gamma^2), (0, 1) for q, nothing mixed.
//   - into the lab (Lorentz): a boost with speed b stretches a 4-vector (T, Y) to
//     |t| <= g (T + b Y), |x| <= g (Y + b T), and the combination |t + n.x| <= g (1 + v.n)(T + Y) for a
//     unit n (the Doppler factor of the boost is at most g (1 + b)); g = 1, b = 0 for the carry.
//   - Lambda is not taken at its worst over the motion: it is computed exactly at the three
//     corners (worldlineRate at each corner's crossing) and carried over the triangle by its
//     Lipschitz bound L_Lambda = c_ss G + c_sq + |x_s| L_F / rho_min (a hyperplane: t_ss G + t_sq),
//     G = c_q / Lambda_min bounding |sigma'|, L_F = |x_s| G + |x_q| bounding |x.|; likewise
//     rho >= min_i rho_i - L_F d and sigma within G d of the corners' (the window of an
//     acceleration's rates), d the longest side. These bounds depend on one another; a guess
//     Lambda_min (first 0.9 times the corners' least) is accepted when min_i Lambda_i - L_Lambda d >
//     Lambda_min and G d is inside the window, which makes them hold on the whole triangle (a point
//     where one of them first failed would be reached from a corner along a segment on which all
//     hold, a contradiction); else the guess moves toward min_i Lambda_i - 1.05 L_Lambda d, at least
//     halving (at most 24 rounds: then no bound, INFINITY, and the caller splits).
//   - the boost's Doppler factor for the cone's combination t + n.x is g (1 + v.n), not taken at its
//     worst g (1 + b): v.n is guessed a hundredth of the way from the corners' largest to b and
//     checked like Lambda (n turns by at most L_F d / rho_min over the triangle); so a part that
//     moves toward the camera, where Lambda is small, gets the small factor g (1 - b) it has.
//   - K = |x..| + |shear| |t..| <= |x_s| S2 + x_ss G^2 + 2 x_sq G + |shear| (t_s S2 + t_ss G^2 + 2 t_sq G),
//     S2 = (c_ss G^2 + 2 c_sq G + L_F^2 / rho_min) / Lambda_min bounding |sigma''| (a hyperplane:
//     (t_ss G^2 + 2 t_sq G) / Lambda_min), all per |u|^2. (shear: the finite model's moving camera,
//     lightcone.h; the callers refuse it for these motions, so it is 0 in practice.)
// A Born-rigid acceleration on the cone (relativistic). The worst-case rates above lose the
// hyperbolae's structure (a factor of about e^(3 |a| s) / Lambda-hat^2); in the start frame (the
// corners' events and the camera's boosted back about (t0, X0)) the terms close by themselves.
// After t0, with xi = 1/|a| + q.k, ch, sh of |a| s, mu = k.n, all per |u| = 1:
//   - E_s = xi |a| (ch, k sh), E_ss = xi |a|^2 (sh, k ch), E_q u = ((k.u) sh, u + k (k.u)(ch - 1)),
//     E_sq u = ((k.u) / xi) E_s; so Lambda = xi |a| Lh, Lh = ch + mu sh (the Doppler part), and
//     (t_sq + n.x_sq) u = (k.u) Lambda / xi.
//   - c = t_q + x_q^T n = n + k (sh + mu (ch - 1)) has |c|^2 = (mu ch + sh)^2 + 1 - mu^2 = Lh^2, so
//     |sigma'| = |c.u| / Lambda <= 1 / (xi |a|) exactly (the proper time xi |a| s is 1-Lipschitz in
//     q); before t0 (at rest in the start frame) Lambda = 1, c = n, |sigma'| <= 1. So sigma moves at
//     most G = max(1, 1 / (xi_lo |a|)) per unit length: the window is the corners' s -+ G d.
//   - putting Lambda sigma'' into x.. and t.., the mixed terms cancel (E_sq is along E_s) and
//     ch Lh - sh (sh + mu ch) = 1, sh Lh - ch (sh + mu ch) = -mu leave
//         x.. = k (xi |a|^2 sigma'^2 - sh P / rho) / Lh,   t.. = -(mu xi |a|^2 sigma'^2 + ch P / rho) / Lh,
//     with xi |a|^2 sigma'^2 <= 1 / xi; before t0, x.. = 0 and t.. = -P / rho.
//   - x. = u - k ((k.u)(ch - 1) + (n.u) sh) / Lh (the same substitution), so
//     |x.| <= min(e^(|a| s), 1 + (e^(|a| s) - 1) / Lh) (the first: |x_q u| <= ch, |x_s sigma'| <= sh),
//     P <= |x.|^2, and rho >= min_i rho_i - |x.| d.
//   - Lh' = |a| sigma' (sh + mu ch) + sh mu', |sh + mu ch| <= Lh (Lh^2 - (sh + mu ch)^2 = 1 - mu^2),
//     |mu'| <= |x.| / rho: Lh' >= -Lh / xi_lo - C, C = sh |x.| / rho_min, so along a segment of
//     length d from a corner Lh >= (min_i Lh_i + C xi_lo) e^(-d / xi_lo) - C xi_lo (Gronwall; Lh is 1
//     before t0 and continuous at t0). |x.| is taken first as e^(|a| S) (no Lh needed), then by its
//     Lh form with the Lh that gave; when the first does not close, with a guess Lh >= min_i Lh_i / 2
//     accepted when the carry returns more (the bootstrap argument of Lambda above).
//   - with S the window's end (ch, sh, e^(|a| S) at their largest there) the start frame's
//     |x..| <= X = (1 / xi_lo + sh P / rho_min) / Lh_min, |t..| <= T = (1 / xi_lo + ch P / rho_min) / Lh_min
//     (P / rho_min alone for T before t0, X = 0), and into the lab (x.. along k before the boost)
//     K = X |k + (g - 1)(k.v^)v^| + g b T (+ |shear| g (T + |v.k| X)).
// No guessed Lambda_min, no worst-case Doppler factor: what is loose is |x.| and Lh taken at their
// worst over the piece, which a sub-piece's own bound shortens.
// The use: for the linear interpolant L of F on a triangle with exact corners, and any point
// p = sum l_i q_i, Taylor's theorem with integral remainder from p to each corner gives
// |F(p) - L(p)| <= (K / 2) sum_i l_i |q_i - p|^2 = (K / 2) sum_{i<j} l_i l_j |q_i - q_j|^2 <= K d^2 / 6.
//
// Keyframed paths (keyed.h). Within one key segment the path is, in its own frame (F_V for
// relativistic and contracted, the lab for finite and instant), Y(s) = P_k + u (s - s_k) + R(s) Q_k q:
// a straight carry at the segment's velocity u plus a turn at the constant rate w about a fixed axis
// (slerp). At a fixed s that is affine in q, and its rates are those of the Galilean carry of a spin
// above, taken in the path's own frame: (T, Y)_s = (1, u + w x R Q q) <= (1, |u| + w rho),
// (T, Y)_ss <= (0, w^2 rho), (T, Y)_q <= (0, 1), (T, Y)_sq <= (0, w), rho the corners' largest
// distance from the axis after Q_k (convex, so the triangle's). Relativistic and contracted then
// boost that frame's events to the lab with V about (t0, X0): the same boost as the spin's, so
// "into the lab" above applies unchanged (g, b those of V); finite and instant carry in the lab
// (g = 1, b = 0). So a piece whose emission times all lie in one segment has the bound above with
// that segment's rates. The window of s ([s_lo - spread, s_hi + spread], checked like an
// acceleration's: sigma within G d of the corners') may meet several segments; every rate is then
// the largest over them, and Lambda is bounded per segment: Lambda_j(q), the cone's combination of
// segment j's rates (its motion extended past its keys, keyed.h keyedSegmentLocal) at q's
// exact event, is computed at the corners for every segment j in the window and is Lipschitz with
// the L_Lambda above (its derivative along a line is (t_ss + n.x_ss)_j sigma' + (t_sq + n.x_sq)_j u
// + x_s,j . n', each term bounded as there), so the bootstrap above bounds every Lambda_j, hence
// the true Lambda (the active segment's) below by Lambda_min. Between kinks along any line F is C2
// with that K.
// Across a key time s_i the map is continuous (the worldlines are), but its gradient jumps on the
// curve Gamma_i = {q : sigma(q) = s_i} = {q : g(s_i, q) = 0}. There x_q and t_q agree on both sides
// (the pose at s_i), so with c_q = t_q + n.x_q (t_q on a hyperplane) and sigma'_pm = -c_q u / Lambda_pm,
//     [grad F] u = -(c_q u) (x_s+ / Lambda+ - x_s- / Lambda-),
//     x_s+ Lambda- - x_s- Lambda+ = dx Lambda- - x_s- (dt + n.dx)   ((dt, dx) = the jump of (t_s, x_s)),
// so |[grad F] u| <= j(q) |u|, j(q) = |c(q)| D(q), D = |x_s+ / Lambda+ - x_s- / Lambda-| (plus the finite
// model's shear times the same for t_s), all at q's event at s_i, which is affine in q whether or
// not q lies on Gamma_i (keyKink): c = Q_i^T (g V + n + g^2/(g + 1)(V.n) V) (Lorentz; n for the
// carry; g V, or 0, on a hyperplane) and (t_s, x_s)+- the two segments' rates there, boosted.
// j is computed exactly at the three corners and carried over the triangle by its Lipschitz bound:
// |x_q| <= g, so rho >= rho_min - g d and n turns at most g / rho per unit length; c's n-part moves
// at most g times that; (t_s, x_s) at most (g b w, g w) (w the faster turn rate); so Lambda at most
// L = g b w + g w + X g / rho (X the largest |x_s|, carried likewise), each quotient x_s / Lambda at
// most g w / Lambda_lo + X L / Lambda_lo^2 (Lambda_lo = the corners' least minus L d); then
// j <= min_k j(q_k) + (L_c D_max + c_max L_D) d. A key's curve counts only where it may meet the
// triangle (keyMayCross): g(s_i, q) is concave in q (affine on a hyperplane), so corners inside
// the cone keep the triangle inside, and corners outside keep it outside when a corner's tangent
// plane is negative at all three.
// Along the line from p to a corner q_l, f(1) - f(0) - f'(0) is the integral remainder of the C2
// parts plus, for each crossing c of a Gamma_i, the kink [f'] times
// the rest of the way, |q_l - c|; at fixed s_i, t and x are affine in q, so on a line
// t_c - t = |x - C| squares to a quadratic: a line meets Gamma_i at most m_i = 2 times (once on a
// hyperplane, t_c - t linear; a line lying in Gamma_i kinks only at its ends). With
// sum_l l_l |q_l - p| <= sqrt(sum_l l_l |q_l - p|^2) <= d / sqrt(3):
//     |F(p) - L(p)| <= K d^2 / 6 + sum_i min(m_i j_i d / sqrt(3), W_i),
// the sum over the keys in the window whose curve may meet the triangle, W_i the same key's term
// weighted by where the lines can cross it (cheaper for a key whose curve passes near a corner or
// outside most of the triangle: a sampled cubic path's many keys), term by term:
//   - g_i(q) = g(s_i, q) is concave with grad g_i = -c (c = t_q + n.x_q, as above) and its second
//     derivative along a unit direction in [-H, 0], H = g^2 / rho_lo (|x_q| <= g, rho >= rho_lo =
//     the corners' least rho at s_i minus g d); so g_i lies between its affine interpolant A on the
//     corners and A + eps, eps = H d^2 / 6 (Taylor from p to the corners, as for K).
//   - a crossing y on the segment from p to corner q_l leaves the remainder |[grad F] (q_l - y)| =
//     D(y) |c(y).(q_l - y)|, and along that segment h = g_i from y (h(0) = 0, h(1) = g_l = g_i(q_l))
//     gives c(y).(q_l - y) = -h'(0) in [-g_l - e, -g_l]: at most D_hi (|g_l| + e), e = H d^2 / 2,
//     D_hi = min_k D(q_k) + L_D d (keyKink's Lipschitz carry of D).
//   - only sign changes of g_i kink the map, and {g_i > 0} meets a segment in an interval: from p
//     with g_i(p) > 0 one crossing to each corner with g_l <= 0, none to the others; from p with
//     g_i(p) <= 0 one to each corner with g_l > 0 and none or two to the others, two only if h
//     rises above 0, which A + eps (largest at the segment's ends) rules out when A(p) <= -eps and
//     g_l <= -eps.
//   - with P = sum_{g_l > 0} l_l g_l <= lambda a, N = sum_{g_l <= 0} l_l |g_l| <= (1 - lambda) b
//     (a, b the corners' largest g_l and -g_l, lambda the positive corners' weight) and A(p) = P - N:
//     g_i(p) > 0 gives N < P + eps and the cost N + e; g_i(p) <= 0 gives P <= N and the cost
//     P + 2 eps + 2 e when A(p) <= -eps, P + 2 N + 2 e <= 3 P + 2 eps + 2 e otherwise. With
//     min(P, N) <= min(lambda a, (1 - lambda) b) <= a b / (a + b):
//         W_i = D_hi (3 a b / (a + b) + 2 eps + 2 e)   (the weights l_l summed against the crossings).
//     For a curve across the middle (a = b = |c| d / 2) that is 0.75 D |c| d against the length
//     term's 1.15; it vanishes as a key's curve approaches a corner (a or b -> 0) but for e. The kink term is linear in d: a piece that
// straddles a key passes once it is about T / (m j) wide, so refinement concentrates where the
// emission time crosses a key, and a sampled CUBICSPLINE path (many keys, each with a small jump)
// pays for the sum of its small jumps, about its velocity change over the window, not for the count.
// On a hyperplane (the contracted model) the kink term is taken exactly instead, term by term:
//   - g_i(q) = t_c - t(s_i, q) is affine in q (t is, at a fixed s), so Gamma_i is a plane and its
//     normal is the kink's own direction: c = t_q = -grad g_i, and [grad F] u = -(c.u) Dv with
//     Dv = x_s+ / Lambda+ - x_s- / Lambda- (Lambda = t_s), |Dv| = D above.
//   - the segment from p to corner q_l crosses Gamma_i once exactly when g_i(p), g_i(q_l) differ in
//     sign, at a point y with g_i(y) = 0; its remainder there is |[grad F] (q_l - y)| =
//     D(y) |c.(q_l - y)| = D(y) |g_i(q_l) - g_i(y)| = D(y) |g_i(q_l)|: no |c| |q_l - y| (Cauchy-Schwarz
//     on a direction the plane may not be across) and no per-length constant at all.
//   - summed with the weights l_l, with g_i(p) = sum_l l_l g_l (affine): the corners on the other
//     side of p weigh min(P, N), P = sum_{g_l > 0} l_l g_l <= lambda a, N = sum_{g_l < 0} l_l |g_l|
//     <= (1 - lambda) b (a, b the largest g_l and -g_l, lambda the weight of the positive corners),
//     and min(lambda a, (1 - lambda) b) <= a b / (a + b) (equal at lambda = b / (a + b)).
//   - D(y) at a point of the triangle: at most min_k D(q_k) + L_D d, L_D of the cone's argument
//     with n = 0 (Lambda = t_s moves at most g b w per unit length); the shear's part of D is 0
//     there (t_s / Lambda = 1 on both sides).
// So on a hyperplane |F(p) - L(p)| <= K d^2 / 6 + sum_i (min_k D_i(q_k) + L_D d) a_i b_i / (a_i + b_i),
// 0 for a key whose plane the corners do not straddle (a_i b_i = 0). For a plane across the
// triangle (a = b = |c| d / 2 at most) that is D |c| d / 4 against the cone's D |c| d / sqrt(3), and
// smaller still for a plane that cuts a corner off; the corners' a, b are exact (no Lipschitz
// carry of c), and without a turn D is constant (L_D = 0).
// For uniform motion (no curvature terms) K is the light delay's Hessian term of chord_error.h,
// looser by the worst angles taken separately (G, L_F); worldline_refine.h therefore measures the
// error at a sub-grid of exact points and uses K only for what lies between them.
#pragma once

#include "mesh4d/event.h"
#include "mesh4d/lightcone.h"
#include "mesh4d/motion/worldline.h"

namespace mesh4d {

// A corner of a rest triangle with its exact crossing: the rest point, the crossing's lab event and
// object time s, its distance rho to the camera (0 on a hyperplane) and its Lambda (above).
struct CornerCrossing {
    Vec3 q;
    Event event;
    double s = 0;
    double rho = 0;
    double lambda = 0;
};

// The exact crossing of q's worldline with `view` and its terms (crossWorldline, worldlineRate).
// ok = false when the search failed (NaN or infinite input).
CornerCrossing cornerCrossing(const ViewSurface& view, const Motion& m, const Vec3& q, bool* ok);

// The bound of one rest triangle: K above (per |u|^2) and, for a keyframed path, the kink term
// over the keys its emission times may cross (light-seconds; on the cone sum_i min(m_i j_i d / sqrt(3), W_i),
// on a hyperplane the straddle term above; 0 for the other motions), so that
// |F - L| <= K d^2 / 6 + kink on the triangle, d its longest side.
struct PieceBound {
    double K = INFINITY;
    double kink = 0;
};

// The bound for the rest triangle with these corners (K = INFINITY when none holds: a triangle
// that may reach the camera, or too large for the guesses to close). `shear_speed`: |view.shear|.
// Precondition: the motion is not uniform and every corner's worldline is timelike.
PieceBound pieceBound(const Motion& m, const ViewSurface& view, double shear_speed, const CornerCrossing c[3]);

}  // namespace mesh4d
