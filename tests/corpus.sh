#!/bin/sh
# The larger corpus run (`make corpus`; not part of `make test`): converts every mesh and GLB under
# ../shared/data and, where Debian's assimp-testmodels is installed, every model in /usr/share/assimp/models
# that assimp reads, each under a time limit, and reports the conversion rate and how many got a face.
# A failure must be one clean "rouge-pack:" line; a crash, a time-out, a NaN frame or a refusal that is not
# one line counts against the run (exit 1). Either source absent: said and skipped.
# Usage: tests/corpus.sh [BUILD_DIR]   (RS_CORPUS_POINTS, default 50000; RS_CORPUS_SECONDS, default 60)
build=${1:-build}
pack="$build/rouge-pack"
points=${RS_CORPUS_POINTS:-50000}
limit=${RS_CORPUS_SECONDS:-60}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
[ -x "$pack" ] || { echo "corpus: $pack not built"; exit 1; }

list="$tmp/list"
: >"$list"
if [ -d ../shared/data ]; then
    find ../shared/data -type f \( -name '*_mesh.ply' -o -iname '*.glb' -o -iname '*.obj' -o -iname '*.fbx' \) | sort >>"$list"
else
    echo "skip - ../shared/data absent"
fi
if [ -d /usr/share/assimp/models ]; then
    # Models only: textures, materials and the like are read through the models that name them.
    find /usr/share/assimp/models -type f ! \( -iname '*.png' -o -iname '*.jpg' -o -iname '*.jpeg' -o -iname '*.bmp' \
        -o -iname '*.tga' -o -iname '*.dds' -o -iname '*.mtl' -o -iname '*.txt' -o -iname '*.bin' -o -iname '*.gif' \
        -o -iname '*.tif' -o -iname '*.skeleton' -o -iname '*.material' -o -iname '*.md' -o -iname '*.zip' \) | sort >>"$list"
else
    echo "skip - /usr/share/assimp/models absent (apt-get install assimp-testmodels)"
fi

total=0 ok=0 faces=0 refused=0 bad=0
while IFS= read -r f; do
    total=$((total + 1))
    timeout -k 5 "$limit" "$pack" "$f" --points "$points" --no-ao -o "$tmp/out.rsf" >"$tmp/out" 2>"$tmp/err"
    rc=$?
    if [ "$rc" -eq 0 ]; then
        if "$pack" --info "$tmp/out.rsf" 2>&1 | grep -qiw 'nan\|inf'; then
            bad=$((bad + 1)); echo "BAD   $f: a frame that is not finite"
        else
            ok=$((ok + 1))
            if grep -q '^ *confidence' "$tmp/out"; then
                faces=$((faces + 1))
                echo "face  $f: $(sed -n 's/^ *confidence *//p' "$tmp/out")"
            else
                echo "model $f"
            fi
        fi
    elif [ "$rc" -eq 1 ] && [ "$(wc -l <"$tmp/err")" -eq 1 ] && grep -q '^rouge-pack: ' "$tmp/err"; then
        refused=$((refused + 1)); echo "no    $f: $(cut -c1-200 "$tmp/err")"
    else
        bad=$((bad + 1)); echo "BAD   $f: exit $rc$([ "$rc" -eq 124 ] && echo " (over ${limit} s)"): $(head -c 200 "$tmp/err" | tr '\n' ' ')"
    fi
    rm -f "$tmp/out.rsf"
done <"$list"
[ "$total" -gt 0 ] || { echo "corpus: nothing to convert"; exit 0; }
echo "corpus: $ok of $total converted ($(awk -v a="$ok" -v b="$total" 'BEGIN { printf "%.0f", 100 * a / b }') %), $faces with a face; $refused refused in one line; $bad crashed, timed out or not finite"
[ "$bad" -eq 0 ]
