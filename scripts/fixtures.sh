#!/usr/bin/env bash
# Regenerate every mesh fixture in tests/fixtures/ from geo/*.geo with the gmsh CLI.
#
#   scripts/fixtures.sh            # uses the project venv's gmsh wheel
#   GMSH="gmsh" scripts/fixtures.sh
#
# GMSH:   the gmsh command, split on spaces (default: the venv python running the venv's
#         gmsh script, "<repo>/.venv/bin/python <repo>/.venv/bin/gmsh"; the wheel's script
#         must be run with the venv python).
# PYTHON: a python3 for the post-processing steps, inverted_tet.msh and sliver_tet.msh (standard library
#         only; default: <repo>/.venv/bin/python if it exists, else python3).
#
# Each fixture, its parameters and groups are listed in tests/fixtures/README.md; keep it
# in step with this file. A gmsh run that prints an "Error" line fails the script (gmsh
# itself exits 0 on .geo errors).
set -euo pipefail

root="$(cd "$(dirname "$0")/.." && pwd)"
GMSH="${GMSH:-$root/.venv/bin/python $root/.venv/bin/gmsh}"
read -r -a gmsh_cmd <<< "$GMSH"
if [[ -z "${PYTHON:-}" ]]; then
  if [[ -x "$root/.venv/bin/python" ]]; then PYTHON="$root/.venv/bin/python"; else PYTHON=python3; fi
fi
geo="$root/geo"
out="$root/tests/fixtures"
mkdir -p "$out"

# mesh NAME GEO [gmsh args...]: mesh geo/GEO in 3D into tests/fixtures/NAME (MSH 4.1).
mesh() {
  local name="$1" script="$2"
  shift 2
  local log
  log="$(mktemp)"
  if ! "${gmsh_cmd[@]}" "$geo/$script" -3 -format msh41 -nopopup "$@" -o "$out/$name" >"$log" 2>&1 \
     || grep -q '^Error' "$log"; then
    echo "fixtures.sh: gmsh failed on $script for $name:" >&2
    grep -E '^(Error|Warning)' "$log" >&2 || tail -20 "$log" >&2
    rm -f "$log"
    exit 1
  fi
  rm -f "$log"
  printf '%-28s %8d bytes\n' "$name" "$(wc -c < "$out/$name")"
}

mesh boxes_hex_4x3.msh        boxes.geo -setnumber nl 4 -setnumber nu 3 -setnumber nz 2
mesh boxes_hex_4x3_binary.msh boxes.geo -setnumber nl 4 -setnumber nu 3 -setnumber nz 2 -bin
mesh boxes_hex_7x5.msh        boxes.geo -setnumber nl 7 -setnumber nu 5 -setnumber nz 2
mesh boxes_hex_3x3.msh        boxes.geo -setnumber nl 3 -setnumber nu 3 -setnumber nz 2
mesh boxes_tet.msh            boxes.geo -setnumber nl 4 -setnumber nu 3 -setnumber nz 2 -setnumber tets 1
mesh incline_hex.msh          incline.geo
mesh bars_hex.msh             bars.geo -setnumber n 20 -setnumber nt 1
mesh socket_tet.msh           socket.geo -setnumber hp 0.2 -setnumber hs 0.3
mesh prism_hex.msh            prism.geo -setnumber n 50 -setnumber nt 1
mesh cantilever_hex.msh       cantilever.geo -setnumber nx 20 -setnumber ny 1 -setnumber nz 2
mesh column_hex.msh           column.geo -setnumber nz 10 -setnumber nw 1
mesh wedge_coarse.msh         wedge.geo -setnumber hw 8 -setnumber hr 30
# the arch dam's coarse variant (docs/dam.md): 29 monoliths, 28 joints, foundation block
mesh arch_dam_coarse.msh      arch_dam.geo -setnumber h 20 -setnumber ht 3.4 -setnumber hr 40 -setnumber hrf 200
# the same with its meshed water (issue 28: reservoir.model "fe_incompressible", pipelines/dam_coarse_fe.json)
mesh arch_dam_coarse_water.msh arch_dam.geo -setnumber h 20 -setnumber ht 3.4 -setnumber hr 40 -setnumber hrf 200 -setnumber water 1

# malformed.msh: boxes_hex_4x3.msh cut 5 lines into its $Elements section (no $EndElements).
awk '{ print } /^\$Elements/ { cut = NR + 5 } cut && NR >= cut { exit }' \
  "$out/boxes_hex_4x3.msh" > "$out/malformed.msh"
printf '%-28s %8d bytes\n' malformed.msh "$(wc -c < "$out/malformed.msh")"

# inverted_tet.msh: boxes_tet.msh with the last two nodes of the first tet of block:upper
# swapped (a negative Jacobian). Prints the tag of that element; README records it.
"$PYTHON" - "$out/boxes_tet.msh" "$out/inverted_tet.msh" <<'PY'
import sys

src, dst = sys.argv[1], sys.argv[2]
lines = open(src).read().split("\n")
idx = {l: i for i, l in enumerate(lines) if l.startswith("$")}

def section(name):
    return idx["$" + name] + 1, idx["$End" + name]

# physical tag of "block:upper" (dim 3)
a, b = section("PhysicalNames")
phys = [l.split(maxsplit=2) for l in lines[a + 1:b]]
upper = next(int(t) for d, t, n in phys if d == "3" and n.strip('"') == "block:upper")

# volume entity carrying that physical tag
a, b = section("Entities")
n_pts, n_cur, n_srf, n_vol = map(int, lines[a].split())
vols = lines[a + 1 + n_pts + n_cur + n_srf:a + 1 + n_pts + n_cur + n_srf + n_vol]
def phys_tags(l):
    f = l.split()
    k = int(f[7])
    return int(f[0]), [int(x) for x in f[8:8 + k]]
entity = next(t for t, p in map(phys_tags, vols) if upper in p)

# first element of the (dim 3, entity, tet4) block
a, b = section("Elements")
i = a + 1
while i < b:
    dim, tag, etype, n = map(int, lines[i].split())
    if dim == 3 and tag == entity and etype == 4:
        f = lines[i + 1].split()
        f[3], f[4] = f[4], f[3]
        lines[i + 1] = " ".join(f) + " "
        print(f"{'inverted_tet.msh':<28s} element {f[0]} of block:upper inverted (nodes 3 and 4 swapped)")
        break
    i += n + 1
else:
    sys.exit("fixtures.sh: no tet4 block for block:upper in " + src)
open(dst, "w").write("\n".join(lines))
PY

# sliver_tet.msh: boxes_tet.msh with the top corner node (1, 1, 0.5) of block:upper moved down
# to z = 0.27 (0.23 m of its 0.25 m layer): one tet4 under it is flattened to a sliver (scaled
# Jacobian 0.04), none inverted. The stable step's critical element (tests/all/outputs.rs).
"$PYTHON" - "$out/boxes_tet.msh" "$out/sliver_tet.msh" <<'PY'
import sys

src, dst = sys.argv[1], sys.argv[2]
lines = open(src).read().split("\n")
a, b = lines.index("$Nodes") + 1, lines.index("$EndNodes")
moved = 0
for i in range(a, b):
    f = lines[i].split()
    if len(f) == 3 and all(abs(float(x) - y) < 1e-9 for x, y in zip(f, (1.0, 1.0, 0.5))):
        lines[i] = f"{f[0]} {f[1]} 0.27"
        moved += 1
if moved != 1:
    sys.exit(f"fixtures.sh: {moved} nodes at (1, 1, 0.5) in {src}, expected 1")
open(dst, "w").write("\n".join(lines))
print(f"{'sliver_tet.msh':<28s} node (1, 1, 0.5) of block:upper moved to z = 0.27")
PY
