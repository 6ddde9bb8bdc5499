// `apparent measure SCENE [--model M] [--frames A:B] [--marker NAME]`: what the pictures show,
// measured on the apparent meshes themselves (issue 38: the Vienna photographs of Hornof et al.,
// Commun. Phys. 8, 161 (2025), reproduced and read off as numbers). Per model, frame and object:
//
//   extent     the apparent mesh's bounding box in the lab, and its extent in image coordinates:
//              (x - C).r and (x - C).u on the image plane through the camera (orthographic camera,
//              scene units), or (x - C).r / (x - C).f and (x - C).u / (x - C).f (perspective: the
//              tangent plane at distance 1); r, u, f the camera's right, up and forward axes.
//   rotation   the turn about the view's vertical axis u that the picture shows: each triangle's
//              projected area along f (signed, > 0 facing the camera) over its area in the rest
//              mesh is c = -n'.f, n' its rest normal n turned by the rotation. With n = (n_r, n_u,
//              n_b) in the basis (r, u, b = -f), a right-handed turn by theta about u gives
//                  c = n_b cos(theta) - n_r sin(theta),
//              linear in (C, S) = (cos theta, sin theta): a least-squares fit over the triangles,
//              weighted by rest area, gives theta = atan2(S, C) (degrees, positive: the front turned
//              towards +r), the residual (the weighted root mean square of c less that of the pure
//              turn by theta) and
//              |(C, S)| (1 for a picture that is exactly a turned rest shape). Exact for the
//              orthographic camera: a body moving at v normal to f is seen turned by asin|v| (the
//              far-field Terrell rotation, mesh4d/lightcone.h); the projection along f is used for a
//              perspective camera too, where it is the rotation of a far, small object only.
//              Faces facing u (top, bottom) do not turn (c = 0) and add only to the residual.
//   outline    about the centre of the image extent, the outline's radius in kOutlineDirections
//              directions (the support function of the projected points, less the centre's): its
//              largest (the rim radius) and smallest value and their ratio, the roundness (1 for a
//              circle; a sphere meshed with vertices within angle a of every point is round within
//              1 - cos a).
//   marker     with --marker NAME, that object's image centre (the mean of its apparent points'
//              image coordinates: for an affine picture the image of its rest vertices' mean): its
//              distance from each other object's outline centre as a fraction of that object's rim
//              radius, and its direction.
//
// The apparent points are those `render` writes (the same cut, pipeline/stage/frame_cut.h), so the
// numbers are those of its PLY files.
#pragma once

#include <array>
#include <iosfwd>
#include <string>
#include <vector>

#include "mesh4d/slice.h"
#include "pipeline/stage/stage.h"

namespace apparent {

constexpr int kOutlineDirections = 720;

// The camera's axes (raytrace.h pixelDirection's): right r, up u, forward f.
struct ImageAxes {
    mesh4d::Vec3 right, up, forward, position;
    bool orthographic = false;
};
ImageAxes imageAxes(const CameraSpec& camera);

// The image coordinates of lab point x (above).
std::array<double, 2> imagePoint(const ImageAxes& axes, const mesh4d::Vec3& x);

struct ApparentMeasure {
    size_t points = 0, triangles = 0;
    mesh4d::Vec3 lo, hi;                          // lab bounding box
    std::array<double, 2> image_lo{}, image_hi{};  // image extent
    std::array<double, 2> centre{};                // middle of the image extent
    double rotation_deg = 0, rotation_residual = 0, rotation_scale = 0;
    bool has_rotation = false;                     // some triangle with rest area
    double rim_radius = 0, min_radius = 0;         // the outline's largest and smallest radius
    std::array<double, 2> mean{};                  // mean image point (the marker's position)
};

// The measures of one object's apparent mesh (its rest_points give the rest areas and normals).
// Empty mesh: points = 0 and nothing else set.
ApparentMeasure measureApparent(const mesh4d::ApparentMesh& mesh, const ImageAxes& axes);

// The outline radius of `mesh` (measured as `m`) towards the unit image direction (dx, dy): the
// support function of its image points less the centre's.
double outlineRadius(const mesh4d::ApparentMesh& mesh, const ImageAxes& axes, const ApparentMeasure& m, double dx,
                     double dy);

struct MeasureSettings {
    StageOptions stage;        // scene, --model (default the scene's; a list or all), --frames, limits
    bool has_frames = false;   // --frames given; otherwise 5 frames spread over the scene
    std::string marker;        // --marker NAME
    bool quiet = false;
};

// Prints the table (one line per model, frame and object, columns as above). Exit codes as render's;
// --marker naming no object: 2.
int measure(const MeasureSettings& settings, std::ostream& out, std::ostream& err);

}  // namespace apparent
