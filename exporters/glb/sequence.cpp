// The sequence's glTF model built frame by frame (SequenceModel, glb.h): the camera node, each
// frame's node and meshes, index lists shared with the previous frame, and with meshopt the runs
// of frames that are morph targets of their run's first mesh (frame coherence, gltf.h).
#include <algorithm>
#include <cmath>
#include <cstring>

#include <tiny_gltf.h>

#include "exporters/glb/glb.h"

namespace apparent::glb {

namespace {

using mesh4d::Vec3;

// Rotation quaternion (x, y, z, w) of the camera node: glTF cameras look down local -Z with +Y
// up, so the node's axes are right = f x up, up' = right x f, back = -f.
std::vector<double> cameraRotation(const ExportCamera& cam) {
    const Vec3 f = (cam.look_at - cam.position) / mesh4d::norm(cam.look_at - cam.position);
    const Vec3 r = mesh4d::cross(f, cam.up) / mesh4d::norm(mesh4d::cross(f, cam.up));
    const Vec3 u = mesh4d::cross(r, f);
    const Vec3 b = -f;
    // Matrix columns r, u, b; standard matrix-to-quaternion conversion choosing the largest term.
    const double m00 = r.x, m01 = u.x, m02 = b.x, m10 = r.y, m11 = u.y, m12 = b.y, m20 = r.z, m21 = u.z, m22 = b.z;
    const double trace = m00 + m11 + m22;
    double x, y, z, w;
    if (trace > 0) {
        const double s = 0.5 / std::sqrt(trace + 1.0);
        w = 0.25 / s; x = (m21 - m12) * s; y = (m02 - m20) * s; z = (m10 - m01) * s;
    } else if (m00 > m11 && m00 > m22) {
        const double s = 2.0 * std::sqrt(1.0 + m00 - m11 - m22);
        w = (m21 - m12) / s; x = 0.25 * s; y = (m01 + m10) / s; z = (m02 + m20) / s;
    } else if (m11 > m22) {
        const double s = 2.0 * std::sqrt(1.0 + m11 - m00 - m22);
        w = (m02 - m20) / s; x = (m01 + m10) / s; y = 0.25 * s; z = (m12 + m21) / s;
    } else {
        const double s = 2.0 * std::sqrt(1.0 + m22 - m00 - m11);
        w = (m10 - m01) / s; x = (m02 + m20) / s; y = (m12 + m21) / s; z = 0.25 * s;
    }
    const double len = std::sqrt(x * x + y * y + z * z + w * w);
    return {x / len, y / len, z / len, w / len};
}

}  // namespace

SequenceModel::SequenceModel(const SequenceInfo& info_, const GlbOptions& options, BinSink* sink)
    : info(info_), b(options, sink), layout(options), shade_doppler(options.shade_doppler) {
    // Step: the camera node (node 0); its clip planes are set in finish().
    gltfjson::Node& node = b.nodes.emplace_back();
    node.name = "camera";
    node.camera = 0;
    node.has_translation = node.has_rotation = true;
    node.translation[0] = info.camera.position.x;
    node.translation[1] = info.camera.position.y;
    node.translation[2] = info.camera.position.z;
    const std::vector<double> q = cameraRotation(info.camera);
    std::copy(q.begin(), q.end(), node.rotation);
    scene_nodes.push_back(0);
    if (options.draco) extensions.push_back("KHR_draco_mesh_compression");
    if (options.meshopt)
        for (const char* e : {"EXT_meshopt_compression", "KHR_mesh_quantization"}) extensions.push_back(e);
    compression = options.draco ? Compression::draco : options.meshopt ? Compression::meshopt : Compression::none;
    previous.resize(info.objects.size());
    // Step: each object's first material: its look's materials where the file carries them, else
    // one; each distinct look's images, textures and samplers once.
    extensions_used = extensions;
    LookPlace next{nullptr};
    for (const ExportObject& o : info.objects) {
        material_first.push_back(materials);
        if (!carriesLook(options, o)) {
            ++materials;
            continue;
        }
        materials += int(o.look->materials.size());
        if (lookPlace(o.look.get())) continue;
        next.look = o.look.get();
        looks.push_back(next);
        next.image += int(o.look->images.size());
        next.texture += int(o.look->textures.size());
        next.sampler += int(o.look->samplers.size());
        for (const std::string& e : o.look->extensions)
            if (std::find(extensions_used.begin(), extensions_used.end(), e) == extensions_used.end())
                extensions_used.push_back(e);
    }
}

const SequenceModel::LookPlace* SequenceModel::lookPlace(const SurfaceLook* look) const {
    for (const LookPlace& p : looks)
        if (p.look == look) return &p;
    return nullptr;
}

void SequenceModel::writeImages() {
    images_written = true;
    for (const LookPlace& p : looks)
        for (const LookImage& image : p.look->images) image_views.push_back(b.addView(image.bytes.data(), image.bytes.size(), 0));
}

bool SequenceModel::addFrame(const ExportFrame& f, const std::vector<PrimitiveData>& data, const double origin[3],
                             double scale, const MeshoptFrame* meshopt, GlbStats* stats, std::string* error) {
    gltfjson::Node node;
    if (!images_written) writeImages();
    if (previous.size() < f.objects.size()) previous.resize(f.objects.size());
    node.name = frameName(f.index);
    // Step: the objects' groups in order: -1 (the frame node) first, then mirrors as they appear.
    std::vector<int> groups;
    for (size_t o = 0; o < f.objects.size(); ++o) {
        if (f.objects[o].triangles.empty()) continue;
        const int g = groupOf(o);
        if (std::find(groups.begin(), groups.end(), g) == groups.end()) groups.push_back(g);
    }
    std::stable_partition(groups.begin(), groups.end(), [](int g) { return g < 0; });
    // Step: which objects share the previous frame's index list (the same list as cut, and the
    // same vertex count): their primitives refer to its accessor.
    std::vector<int> shared(f.objects.size(), -1);
    for (size_t o = 0; o < f.objects.size(); ++o) {
        const Previous& prev = previous[o];
        if (compression != Compression::draco && !f.objects[o].triangles.empty() && prev.accessor >= 0 &&
            data[o].part_first.empty() && prev.same(data[o]))
            shared[o] = prev.accessor;
    }
    // Step (meshopt): a frame that continues the open run becomes a morph target of its mesh.
    if (compression == Compression::meshopt && meshopt) {
        std::string target_error;
        if (morphTarget(f, data, scale, *meshopt, shared, groups, &target_error)) {
            morph_nodes.push_back({b.nodes.size(), run.targets, runs.size() - 1});
            node.mesh = run.mesh;
            return endFrame(f, &node, origin, scale);
        }
        if (!target_error.empty()) {
            *error = target_error;
            return false;
        }
    }
    // Step (meshopt): the frame's vertex and normal views, and one index view for the objects
    // that do not share, uint16 unless one of them has more than 65535 vertices.
    int vview = -1, nview = -1;
    std::vector<int> meshopt_indices(f.objects.size(), -1);
    std::vector<std::vector<int>> meshopt_parts(f.objects.size());  // per object with material parts
    if (compression == Compression::meshopt && meshopt && meshopt->count > 0) {
        vview = meshopt->remote ? b.addMeshoptView(meshopt->remote_encoded, meshopt->count, meshopt->stride, false)
                                : b.addMeshoptView(meshopt->encoded, meshopt->count, meshopt->stride, false);
        if (!meshopt->normals_inline)
            nview = meshopt->remote ? b.addMeshoptView(meshopt->remote_normals, meshopt->count, kMeshoptNormalStride,
                                                       false, true)
                                    : b.addMeshoptView(meshopt->encoded_normals, meshopt->count, kMeshoptNormalStride,
                                                       false, true);
        size_t size = 2, count = 0, most = 0;
        bool none_shared = true;
        std::vector<size_t> first(f.objects.size(), 0);
        for (size_t o = 0; o < f.objects.size(); ++o)
            if (!f.objects[o].triangles.empty() && shared[o] < 0) {
                most = std::max(most, data[o].packedVertices(layout.stride));
                first[o] = count;
                count += data[o].orderedCount();
            } else if (!f.objects[o].triangles.empty()) {
                none_shared = false;
            }
        if (most > 65535) size = 4;
        if (count > 0) {
            int iview = -1;
            if (meshopt->remote && none_shared) {
                // Every shown object's indices: the stream the other process encoded.
                iview = b.addMeshoptView(meshopt->remote_indices, count, size, true);
            } else {
                // Some objects share theirs (by reference: their lists read back from the spill).
                std::vector<unsigned int> all;
                all.reserve(count);
                for (size_t o = 0; o < f.objects.size(); ++o)
                    if (!f.objects[o].triangles.empty() && shared[o] < 0 &&
                        !appendOrdered(data[o], &all, error))
                        return false;
                std::vector<unsigned char> encoded;
                encodeIndexStream(all, most, &encoded);
                iview = b.addMeshoptView(encoded, all.size(), size, true);
            }
            const int component = size == 2 ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT : TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
            for (size_t o = 0; o < f.objects.size(); ++o)
                if (!f.objects[o].triangles.empty() && shared[o] < 0 && !data[o].part_first.empty()) {
                    // One accessor per material part, each part's triangles one range of the list.
                    const std::vector<uint32_t>& parts = data[o].part_first;
                    for (size_t p = 0; p + 1 < parts.size(); ++p)
                        meshopt_parts[o].push_back(b.addAccessor(iview, component, false,
                                                                 3 * size_t(parts[p + 1] - parts[p]),
                                                                 (first[o] + 3 * size_t(parts[p])) * size));
                    meshopt_indices[o] = meshopt_parts[o].front();
                } else if (!f.objects[o].triangles.empty() && shared[o] < 0) {
                    meshopt_indices[o] = b.addAccessor(iview, component, false, data[o].orderedCount(), first[o] * size);
                }
        }
    }
    std::vector<bool> shown(f.objects.size(), false);
    for (const int group : groups) {
        gltfjson::Mesh mesh;
        mesh.name = group < 0 ? node.name : reflectionName(node.name, mirrorName(group));
        for (size_t o = 0; o < f.objects.size(); ++o) {
            if (f.objects[o].triangles.empty() || groupOf(o) != group) continue;
            gltfjson::Primitive prim;
            Previous& prev = previous[o];
            if (compression == Compression::draco && !data[o].draco.parts.empty()) {
                // Step: one primitive per material, each its own Draco mesh.
                const DracoCoded& c = data[o].draco;
                for (size_t p = 0; p < c.parts.size() && p < data[o].part_material.size(); ++p) {
                    gltfjson::Primitive part;
                    double qerr = 0;
                    if (!b.dracoPrimitive(data[o], &part, &qerr, error, int(p))) {
                        *error = mesh.name + ": " + *error;
                        return false;
                    }
                    part.material = material_first[o] + int(data[o].part_material[p]);
                    mesh.primitives.push_back(std::move(part));
                }
                stats->max_quantization_error = std::max(stats->max_quantization_error, c.quantization_error);
                stats->max_texcoord_error = std::max(stats->max_texcoord_error, c.texcoord_error);
                stats->texcoords = stats->texcoords || c.ids[6] >= 0 || c.ids[7] >= 0;
                shown[o] = true;
                continue;
            } else if (compression == Compression::draco) {
                double qerr = 0;
                if (!b.dracoPrimitive(data[o], &prim, &qerr, error)) {
                    *error = mesh.name + ": " + *error;
                    return false;
                }
                stats->max_quantization_error = std::max(stats->max_quantization_error, qerr);
                stats->max_texcoord_error = std::max(stats->max_texcoord_error, data[o].draco.texcoord_error);
                stats->texcoords = stats->texcoords || data[o].draco.ids[6] >= 0 || data[o].draco.ids[7] >= 0;
            } else if (compression == Compression::meshopt && !meshopt_parts[o].empty()) {
                // Step: one primitive per material, sharing the vertices (never the indices).
                prim = b.meshoptPrimitive(data[o], layout, meshopt->stride, vview, nview, meshopt->first[o],
                                          meshopt_indices[o]);
                stats->texcoords = stats->texcoords || prim.attributes[gltfjson::kTexcoord0] >= 0 ||
                                  prim.attributes[gltfjson::kTexcoord1] >= 0;
                prev = Previous();
                shown[o] = true;
                for (size_t p = 0; p < meshopt_parts[o].size(); ++p) {
                    gltfjson::Primitive part = prim;
                    part.indices = meshopt_parts[o][p];
                    part.material = material_first[o] + int(data[o].part_material[p]);
                    mesh.primitives.push_back(std::move(part));
                }
                continue;
            } else if (compression == Compression::meshopt) {
                prim = b.meshoptPrimitive(data[o], layout, meshopt->stride, vview, nview, meshopt->first[o],
                                          shared[o] >= 0 ? shared[o] : meshopt_indices[o]);
                stats->texcoords = stats->texcoords || prim.attributes[gltfjson::kTexcoord0] >= 0 ||
                                  prim.attributes[gltfjson::kTexcoord1] >= 0;
            } else if (!data[o].part_first.empty()) {
                // Step: one primitive per material, sharing the vertices (never the indices).
                std::vector<int> parts;
                prim = b.plainPrimitive(data[o], -1, &parts);
                prev = Previous();
                shown[o] = true;
                for (size_t p = 0; p < parts.size(); ++p) {
                    gltfjson::Primitive part = prim;
                    part.indices = parts[p];
                    part.material = material_first[o] + int(data[o].part_material[p]);
                    mesh.primitives.push_back(std::move(part));
                }
                continue;
            } else {
                prim = b.plainPrimitive(data[o], shared[o]);
            }
            if (compression != Compression::draco && shared[o] < 0) prev.take(prim.indices, data[o], borrow_indices);
            shown[o] = true;
            prim.material = o < material_first.size() ? material_first[o] : -1;
            mesh.primitives.push_back(std::move(prim));
        }
        b.meshes.push_back(std::move(mesh));
        if (group < 0)
            node.mesh = int(b.meshes.size()) - 1;
        else
            reflections.push_back({frames, mirrorName(group), int(b.meshes.size()) - 1});
    }
    // Sharing is between consecutive frames: an object not shown forgets its index list.
    for (size_t o = 0; o < f.objects.size(); ++o)
        if (!shown[o]) previous[o] = Previous();
    // Step (meshopt): the frame opens a run when later frames may become its morph targets.
    run.mesh = -1;
    if (compression == Compression::meshopt && meshopt && meshopt->count > 0) startRun(f, data, scale, *meshopt, groups, node.mesh);
    if (groups.empty()) return endFrame(f, &node, nullptr, scale);
    return endFrame(f, &node, origin, scale);
}

bool SequenceModel::endFrame(const ExportFrame& f, gltfjson::Node* node, const double* origin, double scale) {
    // Reflections are relative to the same origin: their child nodes need no transform.
    if (origin) {
        node->has_translation = true;
        std::copy(origin, origin + 3, node->translation);
    }
    const double s = frames == 0 ? scale : 0.0;
    node->has_scale = true;
    node->scale[0] = node->scale[1] = node->scale[2] = s;
    frame_scales.push_back(float(scale));
    b.nodes.push_back(std::move(*node));
    scene_nodes.push_back(int(b.nodes.size()) - 1);
    frame_times.push_back(f.t_c);
    if (frames == 0) first_frame = f.index;
    ++frames;
    return true;
}

std::vector<size_t> SequenceModel::shownObjects(const ExportFrame& f) {
    std::vector<size_t> objects;
    for (size_t o = 0; o < f.objects.size(); ++o)
        if (!f.objects[o].triangles.empty()) objects.push_back(o);
    return objects;
}

void SequenceModel::startRun(const ExportFrame& f, const std::vector<PrimitiveData>& data, double step,
                             const MeshoptFrame& mf, const std::vector<int>& groups, int mesh) {
    if (layout.stride != 12 || groups.size() != 1 || groups[0] >= 0 || mesh < 0) return;
    const size_t limit = std::min(kMorphTargetsMost, kMorphVertexTargets / mf.count);
    if (limit == 0) return;
    run.objects = shownObjects(f);
    if (mf.remote) {
        // By reference the records stay where the frame was cut, which made the next frame's target.
        if (!mf.remote_run) return;
    } else {
        std::vector<const PrimitiveData*> shown;
        for (const size_t o : run.objects) shown.push_back(&data[o]);
        if (!runReference(shown, mf.count, mf.normals_inline, true, &run.records, &run.normals)) return;
    }
    run.mesh = mesh;
    run.step = step;
    run.normals_inline = mf.normals_inline;
    run.count = mf.count;
    run.limit = limit;
    run.targets = 0;
    runs.push_back(0);
}

bool SequenceModel::morphTarget(const ExportFrame& f, const std::vector<PrimitiveData>& data, double step,
                                const MeshoptFrame& mf, const std::vector<int>& shared, const std::vector<int>& groups,
                                std::string* error) {
    if (run.mesh < 0 || step != run.step || mf.count != run.count || run.targets >= run.limit) return false;
    if (groups.size() != 1 || groups[0] >= 0) return false;
    const std::vector<size_t> objects = shownObjects(f);
    if (objects != run.objects) return false;
    for (const size_t o : objects)
        if (shared[o] < 0) return false;
    std::vector<size_t> first;
    int lo[3], hi[3];
    int view = -1;
    if (mf.remote) {
        // Made where the frame was cut, against the previous frame's records (runReference).
        if (!mf.targets) {
            *error = "internal: frame " + std::to_string(f.index) + " by reference without its morph target";
            return false;
        }
        const MeshoptFrame::RemoteTarget& t = mf.remote_target[run.targets == 0 && !run.normals_inline ? 0 : 1];
        if (!t.fits) return false;
        size_t v = 0;
        for (const size_t o : objects) {
            first.push_back(v);
            v += data[o].packedVertices(12);
        }
        if (v != run.count) return false;
        std::copy(t.lo, t.lo + 3, lo);
        std::copy(t.hi, t.hi + 3, hi);
        view = b.addMeshoptView(t.encoded, run.count, kMorphStride, false);
    } else {
        std::vector<const PrimitiveData*> shown;
        for (const size_t o : objects) shown.push_back(&data[o]);
        std::vector<unsigned char>& rec = morph_records;
        if (!morphRecords(shown, run.records, run.normals, run.count, &rec, &first, lo, hi)) return false;
        view = b.addMeshoptView(encodeMorphRecords(rec, run.count), run.count, kMorphStride, false);
    }
    // Per primitive the target's three accessors.
    gltfjson::Mesh& mesh = b.meshes[size_t(run.mesh)];
    const double lo_d[3] = {double(lo[0]), double(lo[1]), double(lo[2])};
    const double hi_d[3] = {double(hi[0]), double(hi[1]), double(hi[2])};
    for (size_t j = 0; j < objects.size(); ++j) {
        const size_t nv = data[objects[j]].packedVertices(12);
        const size_t at = first[j] * kMorphStride;
        // POSITION's bounds (required) are the whole frame's: a bound of every primitive's.
        std::array<int, gltfjson::kAttributes>& target = mesh.primitives[j].targets.emplace_back();
        target.fill(-1);
        target[gltfjson::kPosition] = b.addAccessor(view, TINYGLTF_COMPONENT_TYPE_SHORT, true, nv, at, lo_d, hi_d, 3);
        target[gltfjson::kEmissionTime] = b.addAccessor(view, TINYGLTF_COMPONENT_TYPE_FLOAT, false, nv, at + 8);
        target[gltfjson::kNormal] = b.addNormalized(view, TINYGLTF_COMPONENT_TYPE_BYTE, true, nv, at + 12);
    }
    // The frame is now the run's reference for the next one.
    size_t v = 0;
    for (const size_t o : objects) {
        if (mf.remote) break;
        const PrimitiveData& d = data[o];
        std::memcpy(&run.records[12 * v], d.packed.data(), d.packed.size());
        std::memcpy(&run.normals[4 * v], d.packed_snorm.data(), d.packed_snorm.size());
        v += d.packed.size() / 12;
    }
    ++run.targets;
    runs.back() = run.targets;
    return true;
}

std::string SequenceModel::reflectionName(const std::string& frame, const std::string& mirror) {
    return frame + " mirror " + mirror;
}

std::string SequenceModel::mirrorName(int index) const {
    for (const ExportObject& o : info.objects)
        if (o.mirror_index == index && !o.mirror.empty()) return o.mirror;
    return "#" + std::to_string(index);
}

}  // namespace apparent::glb
