#!/usr/bin/env bash
# Opens per-frame PLY output in MeshLab (Debian's meshlabserver, headless under Xvfb) and checks
# what MeshLab itself measures: a closed input that exists throughout must come out as one
# two-manifold component of genus 0 with no holes, and MeshLab must read the vertex quality.
# Usage: meshlab_ply.sh APPARENT_BINARY SOURCE_DIR
set -euo pipefail
apparent=$1
src=$2
command -v meshlabserver >/dev/null || { echo "meshlabserver missing: apt-get install meshlab xvfb xauth (scripts/setup.sh test)"; exit 1; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$apparent" render "$src/data/fixtures/scene_tetra.json" --out "$out" --format ply --model all --quiet
cat > "$out/measures.mlx" <<'MLX'
<!DOCTYPE FilterScript>
<FilterScript>
 <filter name="Compute Geometric Measures"/>
 <filter name="Compute Topological Measures"/>
 <filter name="Colorize by vertex Quality">
  <Param type="RichFloat" value="0" name="minVal"/>
  <Param type="RichFloat" value="0" name="maxVal"/>
  <Param type="RichDynamicFloat" value="0" min="0" max="100" name="perc"/>
  <Param type="RichBool" value="true" name="zeroSym"/>
 </filter>
</FilterScript>
MLX
status=0
for ply in "$out"/*/frame_00002.ply; do
  log="$out/log.txt"
  rm -f "$log"
  xvfb-run -a meshlabserver -i "$ply" -o "$out/colored.ply" -m vc vq -s "$out/measures.mlx" -l "$log" >"$out/stdout.txt" 2>&1 || true
  model=$(basename "$(dirname "$ply")")
  for want in "Mesh is two-manifold" "Mesh has 0 holes" "Genus is 0" "composed by 1 connected component"; do
    if ! grep -q "$want" "$log" 2>/dev/null; then echo "FAIL $model: MeshLab did not report '$want'"; status=1; fi
  done
  # MeshLab wrote the quality back out: the property survived its reader.
  if ! head -c 400 "$out/colored.ply" | grep -q "property float quality"; then
    echo "FAIL $model: MeshLab lost the vertex quality"; status=1
  fi
  area=$(grep -o "Mesh Surface Area is [0-9.]*" "$log" | head -1)
  echo "$model frame 2: MeshLab: two-manifold, genus 0, no holes, 1 component; $area"
done
exit $status
