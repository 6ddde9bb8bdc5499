#include "pipeline/physics.h"

namespace apparent {

mesh4d::Kinematics kinematicsOf(Model m) {
    return (m == Model::Relativistic || m == Model::Contracted) ? mesh4d::Kinematics::Lorentz
                                                                 : mesh4d::Kinematics::Galilean;
}

mesh4d::Motion motionOf(const ObjectSpec& s, Model model) {
    const mesh4d::Kinematics kin = kinematicsOf(model);
    switch (s.speed) {
        case ObjectSpec::Speed::Gamma:
            return mesh4d::makeMotionFromGamma(kin, s.t0, s.position, s.direction, s.gamma);
        case ObjectSpec::Speed::Rapidity:
            return mesh4d::makeMotionFromRapidity(kin, s.t0, s.position, s.direction, s.rapidity);
        case ObjectSpec::Speed::Velocity:
            break;
    }
    return mesh4d::makeMotion(kin, s.t0, s.position, s.velocity);
}

mesh4d::CameraMotion cameraMotionOf(const Scene& scene) {
    return mesh4d::makeCameraMotion(scene.camera.position, scene.camera.velocity);
}

mesh4d::MotionInCameraFrame cameraFrameMotionOf(const ObjectSpec& s, Model model, const Scene& scene) {
    return mesh4d::motionInCameraFrame(motionOf(s, model), cameraMotionOf(scene));
}

mesh4d::MotionInCameraFrame cutMotionOf(const ObjectSpec& s, Model model, const Scene& scene) {
    if (model == Model::Finite) return {motionOf(s, model)};  // cut in the lab, sheared at output (viewAt)
    return cameraFrameMotionOf(s, model, scene);
}

const mesh4d::RestMesh& restInCameraFrame(const mesh4d::RestMesh& rest, const mesh4d::MotionInCameraFrame& m,
                                          mesh4d::RestMesh* storage) {
    if (!m.rotated) return rest;
    *storage = rest;
    for (mesh4d::Vec3& p : storage->positions) p = mesh4d::apply(m.rotation, p);
    return *storage;
}

mesh4d::ViewSurface viewForFrame(const Scene& scene, Model model, long long k) {
    return viewAt(scene, model, frameTime(scene.frames, k));
}

mesh4d::ViewSurface viewAt(const Scene& scene, Model model, double t_c) {
    mesh4d::ViewSurface view;
    view.kind = (model == Model::Finite || model == Model::Relativistic) ? mesh4d::ViewKind::PastCone
                                                                         : mesh4d::ViewKind::Hyperplane;
    view.t_c = t_c;
    // The hyperplane models may look back by the stage's light delay (scene camera.instant_delay).
    if (view.kind == mesh4d::ViewKind::Hyperplane) view.t_c -= scene.camera.instant_delay;
    view.apex = scene.camera.position;
    // The finite model with a moving camera: light moves at c in the lab, so the cone is the lab's,
    // from the camera's lab position at t_c (its proper time, the lab's under Galilean kinematics),
    // and the outputs are sheared into the camera's frame, x' = x - v t (slice.h sliceWorld).
    const mesh4d::CameraMotion camera = cameraMotionOf(scene);
    if (model == Model::Finite && camera.moving()) {
        view.apex = camera.position + camera.velocity * t_c;
        view.shear = camera.velocity;
    }
    return view;
}

}  // namespace apparent
