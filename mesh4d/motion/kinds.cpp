#include "mesh4d/motion/kinds.h"

namespace mesh4d {

extern const KindAnswers kOrbitAnswers;  // orbit.cpp

const KindAnswers* answersOf(const Motion& m) {
    switch (kindOf(m)) {
        case MotionKind::Uniform:
        case MotionKind::Spin:
        case MotionKind::Hyperbolic:
        case MotionKind::Keyed:
            return nullptr;
        case MotionKind::Orbit:
            return &kOrbitAnswers;
    }
    return nullptr;
}

}  // namespace mesh4d
