#include "mesh4d/motion/kinds.h"

namespace mesh4d {

const KindAnswers* answersOf(const Motion& m) {
    switch (kindOf(m)) {
        case MotionKind::Uniform:
        case MotionKind::Spin:
        case MotionKind::Hyperbolic:
        case MotionKind::Keyed:
            return nullptr;
    }
    return nullptr;
}

}  // namespace mesh4d
