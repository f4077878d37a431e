#!/bin/sh
# Third-party models (tests/fixtures/corpus, assimp's BSD test set) through rouge-pack: the non-faces get
# no face (no face regions: every splat `other`), a finite frame from their bounds and a one-line note on
# stderr; the Lee Perry-Smith head export is found as a face with regions; nothing in any header is NaN.
# Then, where ../shared/data is present, its two real scans (skipped when absent). `make corpus` runs the
# larger set (tests/corpus.sh).
build=${1:-build}
pack="$build/rouge-pack"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fx=tests/fixtures/corpus

if [ ! -x "$pack" ]; then echo "FAIL - corpus: $pack not built"; exit 1; fi

# convert NAME FILE POINTS: summary to $tmp/NAME.out, stderr to $tmp/NAME.err, --info to $tmp/NAME.info.
convert() {
    "$pack" "$2" --points "$3" --no-ao -o "$tmp/$1.rsf" >"$tmp/$1.out" 2>"$tmp/$1.err"
    rc=$?
    if [ "$rc" -ne 0 ]; then echo "FAIL - corpus_$1: exit $rc: $(head -c 300 "$tmp/$1.err")"; return 1; fi
    "$pack" --info "$tmp/$1.rsf" >"$tmp/$1.info" 2>&1
    if grep -qiw 'nan\|inf' "$tmp/$1.info" "$tmp/$1.out"; then
        echo "FAIL - corpus_$1: not finite: $(grep -iw 'nan\|inf' "$tmp/$1.info" "$tmp/$1.out" | head -3)"
        return 1
    fi
    return 0
}

not_a_face() {  # NAME FILE
    convert "$1" "$2" 4000 || return
    if ! grep -q '^ *regions *other 100.0%' "$tmp/$1.out"; then
        echo "FAIL - corpus_$1: face regions on a non-face: $(grep regions "$tmp/$1.out")"
    elif [ "$(grep -c 'no face (\|no face found' "$tmp/$1.err")" -ne 1 ]; then
        echo "FAIL - corpus_$1: no one-line 'no face' note on stderr: $(head -c 300 "$tmp/$1.err")"
    else
        echo "ok - corpus_$1: no face, framed by its bounds ($(grep -o 'no face [^;]*' "$tmp/$1.err" | grep -v 'to measure'))"
    fi
}

a_face() {  # NAME FILE POINTS
    convert "$1" "$2" "$3" || return
    conf=$(sed -n 's/^ *confidence *\([0-9.]*\).*/\1/p' "$tmp/$1.out")
    lips=$(sed -n 's/.* lips \([0-9.]*\)%.*/\1/p' "$tmp/$1.out")
    if [ -z "$conf" ] || grep -q 'no face (\|no face found' "$tmp/$1.err"; then
        echo "FAIL - corpus_$1: no face found: $(head -c 300 "$tmp/$1.err")"
    elif ! awk -v c="$conf" -v l="$lips" 'BEGIN { exit !(c >= 0.6 && l > 0.1) }'; then
        echo "FAIL - corpus_$1: confidence $conf, lips $lips% (want >= 0.6 and > 0.1%)"
    else
        echo "ok - corpus_$1: a face, confidence $conf, lips $lips% of the splats"
    fi
}

not_a_face spider "$fx/Spider_binary.stl"
not_a_face wuson "$fx/Wuson.off"
not_a_face sphere_with_hole "$fx/sphereWithHole.stl"
not_a_face cube_uv "$fx/cube_uv.ply"
not_a_face triangle "$fx/triangle.stl"
# A flat model is seen face-on: the triangle lies in z = 0, so the camera looks along z.
if [ -f "$tmp/triangle.info" ]; then
    if grep -q '^ *forward *(0.0000 0.0000 [-]*1.0000)' "$tmp/triangle.info"; then
        echo "ok - corpus_flat_model_seen_face_on"
    else
        echo "FAIL - corpus_flat_model_seen_face_on: $(grep forward "$tmp/triangle.info")"
    fi
fi
# A model from a z-up exporter standing on z (a post 1 x 0.6 x 4): framed z up, not seen from its top.
{
    printf 'v 0 0 0\nv 1 0 0\nv 1 0.6 0\nv 0 0.6 0\nv 0 0 4\nv 1 0 4\nv 1 0.6 4\nv 0 0.6 4\n'
    printf 'f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n'
} >"$tmp/post.obj"
if convert post "$tmp/post.obj" 4000; then
    if grep -q '^ *up *(0.0000 0.0000 1.0000)' "$tmp/post.info"; then echo "ok - corpus_z_up_model_stands_on_z"
    else echo "FAIL - corpus_z_up_model_stands_on_z: $(grep '^ *up' "$tmp/post.info")"; fi
fi
a_face head_obj tests/fixtures/import/head/head.obj 20000

# A file that is no model: one clean line, exit 1, nothing written.
"$pack" tests/fixtures/import/bad_not_a_model.obj -o "$tmp/bad.rsf" >/dev/null 2>"$tmp/bad.err"
rc=$?
if [ "$rc" -eq 1 ] && [ "$(wc -l <"$tmp/bad.err")" -eq 1 ] && grep -q '^rouge-pack: ' "$tmp/bad.err" && [ ! -e "$tmp/bad.rsf" ]; then
    echo "ok - corpus_refusal_is_one_line"
else
    echo "FAIL - corpus_refusal_is_one_line: exit $rc: $(head -c 300 "$tmp/bad.err")"
fi

data=../shared/data
if [ -f "$data/leeperrysmith/head_mesh.ply" ]; then a_face lee_perry_smith "$data/leeperrysmith/head_mesh.ply" 20000
else echo "skip - corpus_lee_perry_smith: $data/leeperrysmith/head_mesh.ply absent"; fi
if [ -f "$data/demosthenes/demosthenes_mesh.ply" ]; then a_face demosthenes "$data/demosthenes/demosthenes_mesh.ply" 20000
else echo "skip - corpus_demosthenes: $data/demosthenes/demosthenes_mesh.ply absent"; fi
