// The tinygltf implementation, compiled once for the whole program (docs/DEPENDENCIES.md section 3:
// Debian's shared libtinygltf has no Draco and clashes with libdraco's copy).
#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>
