# hostile_models.sh — writes the hostile models of issue 23 at test time (sourced by tests/test_robustness.sh;
# nothing big is committed). Each function takes the output path. awk writes the binary ones byte by byte
# (LC_ALL=C: printf "%c" is one byte, 0 included).
#
#   deep_dae F N      COLLADA: a node chain N deep around one triangle
#   self_dae F        COLLADA: a node that instances itself
#   deep_gltf F N     glTF: a node chain N deep ("children": [i + 1]), one triangle as a data: URI
#   deep_glb F N      the same as a GLB (binary container, triangle in the BIN chunk)
#   deep_fbx F N      binary FBX: records nested N deep
#   bomb_gltf F       glTF: 10^4 nodes instancing one 10^4-triangle mesh (10^8 triangles once expanded)
#   bomb_fbx F        binary FBX: a zlib-compressed vertex array claiming 2^28 - 1 doubles (2 GiB) in 8 bytes

# One triangle (0,0,0) (1,0,0) (0,1,0) as 36 bytes of little-endian floats, base64.
HOSTILE_TRI_B64=AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA

deep_dae() {
    LC_ALL=C awk -v n="$2" 'BEGIN {
        print "<?xml version=\"1.0\"?>"
        print "<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">"
        print "<asset><unit meter=\"1\"/><up_axis>Y_UP</up_axis></asset>"
        print "<library_geometries><geometry id=\"g\"><mesh>"
        print "<source id=\"p\"><float_array id=\"pa\" count=\"9\">0 0 0 1 0 0 0 1 0</float_array>"
        print "<technique_common><accessor source=\"#pa\" count=\"3\" stride=\"3\"><param name=\"X\" type=\"float\"/>"
        print "<param name=\"Y\" type=\"float\"/><param name=\"Z\" type=\"float\"/></accessor></technique_common></source>"
        print "<vertices id=\"v\"><input semantic=\"POSITION\" source=\"#p\"/></vertices>"
        print "<triangles count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/><p>0 1 2</p></triangles>"
        print "</mesh></geometry></library_geometries>"
        print "<library_visual_scenes><visual_scene id=\"s\">"
        for (i = 0; i < n; i++) printf "<node id=\"n%d\">\n", i
        print "<instance_geometry url=\"#g\"/>"
        for (i = 0; i < n; i++) print "</node>"
        print "</visual_scene></library_visual_scenes>"
        print "<scene><instance_visual_scene url=\"#s\"/></scene></COLLADA>"
    }' >"$1"
}

self_dae() {
    deep_dae "$1.tmp" 1
    sed -e 's#<library_visual_scenes>#<library_nodes><node id="a" name="a"><instance_geometry url="\#g"/><instance_node url="\#a"/></node></library_nodes><library_visual_scenes>#' \
        -e 's#<instance_geometry url="\#g"/>$#<instance_node url="\#a"/>#' "$1.tmp" >"$1"
    rm -f "$1.tmp"
}

# The glTF JSON of a node chain N deep; $3 is the buffer's "uri" member ("" for a GLB's own BIN chunk).
hostile_gltf_json() {
    LC_ALL=C awk -v n="$1" -v uri="$2" 'BEGIN {
        printf "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":["
        for (i = 0; i < n - 1; i++) printf "{\"children\":[%d]},", i + 1
        printf "{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
        printf "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
        printf "\"min\":[0,0,0],\"max\":[1,1,0]}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
        printf "\"buffers\":[{%s\"byteLength\":36}]}", uri
    }'
}

deep_gltf() {
    hostile_gltf_json "$2" "\"uri\":\"data:application/octet-stream;base64,$HOSTILE_TRI_B64\"," >"$1"
}

deep_glb() {
    hostile_gltf_json "$2" "" >"$1.json"
    # The JSON chunk is padded with spaces to 4 bytes; the BIN chunk is the triangle.
    len=$(wc -c <"$1.json")
    pad=$(((4 - len % 4) % 4))
    printf '%*s' "$pad" "" >>"$1.json"
    len=$((len + pad))
    echo "$HOSTILE_TRI_B64" | base64 -d >"$1.bin"
    LC_ALL=C awk -v j="$len" 'function le32(v) { printf "%c%c%c%c", v % 256, int(v / 256) % 256, int(v / 65536) % 256, int(v / 16777216) % 256 }
        BEGIN { printf "glTF"; le32(2); le32(12 + 8 + j + 8 + 36); le32(j); printf "JSON" }' >"$1"
    cat "$1.json" >>"$1"
    LC_ALL=C awk 'function le32(v) { printf "%c%c%c%c", v % 256, int(v / 256) % 256, int(v / 65536) % 256, int(v / 16777216) % 256 }
        BEGIN { le32(36); printf "BIN%c", 0 }' >>"$1"
    cat "$1.bin" >>"$1"
    rm -f "$1.json" "$1.bin"
}

# FBX 7.4 binary: 27-byte header, then records (u32 end offset, u32 property count, u32 property bytes,
# u8 name length, name, properties, nested records + a 13-byte null record), ended by a null record.
deep_fbx() {
    LC_ALL=C awk -v n="$2" 'function le32(v) { printf "%c%c%c%c", v % 256, int(v / 256) % 256, int(v / 65536) % 256, int(v / 16777216) % 256 }
        function zeros(k,  i) { for (i = 0; i < k; i++) printf "%c", 0 }
        BEGIN {
            printf "Kaydara FBX Binary  %c%c%c", 0, 26, 0; le32(7400)
            for (i = 0; i < n; i++) {
                # Record i starts at 27 + 14 i; the innermost ends at 27 + 14 n, each outer one 13 bytes later.
                le32(27 + 14 * n + 13 * (n - 1 - i)); le32(0); le32(0); printf "%cA", 1
            }
            for (i = 0; i < n - 1; i++) zeros(13)
            zeros(13)
        }' >"$1"
}

bomb_gltf() {
    # 10^4 triangles of zero-filled positions (360000 bytes, an external .bin next to the model).
    head -c 360000 /dev/zero >"${1%.gltf}.bin"
    LC_ALL=C awk -v bin="$(basename "${1%.gltf}.bin")" 'BEGIN {
        printf "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":["
        for (i = 0; i < 10000; i++) printf "%s%d", i ? "," : "", i
        printf "]}],\"nodes\":["
        for (i = 0; i < 10000; i++) printf "%s{\"mesh\":0}", i ? "," : ""
        printf "],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
        printf "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":30000,\"type\":\"VEC3\","
        printf "\"min\":[0,0,0],\"max\":[0,0,0]}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":360000}],"
        printf "\"buffers\":[{\"uri\":\"%s\",\"byteLength\":360000}]}", bin
    }' >"$1"
}

# FBX records as token lists for awk: a number is a byte, "E<n>" the record's end offset (its start + n,
# written as u32 when the record's position is known).
HOSTILE_FBX_AWK='
function le(v,  s) { return (v % 256) " " (int(v / 256) % 256) " " (int(v / 65536) % 256) " " (int(v / 16777216) % 256) }
function str(s,  i, o) { o = ""; for (i = 1; i <= length(s); i++) o = o " " ord[substr(s, i, 1)]; return o }
function tlen(t,  a, n, i, k) { n = split(t, a, " "); k = 0; for (i = 1; i <= n; i++) k += substr(a[i], 1, 1) == "E" ? 4 : 1; return k }
# A record: properties (token list) and children (token list, "" for none: then no null record follows).
function rec(name, nprops, props, kids,  body, t) {
    body = le(nprops) " " le(tlen(props)) " " length(name) str(name) " " props
    if (kids != "") body = body " " kids " " zeros(13)
    t = tlen(body) + 4
    return "E" t " " body
}
function zeros(k,  o, i) { o = "0"; for (i = 1; i < k; i++) o = o " 0"; return o }
function pS(s) { return "83 " le(length(s)) str(s) }
function pL(v) { return "76 " le(v) " 0 0 0 0" }
function pI(v) { return "73 " le(v) }
function emit(t,  a, n, i, pos, v) {
    n = split(t, a, " "); pos = 0
    for (i = 1; i <= n; i++) {
        if (substr(a[i], 1, 1) == "E") {
            v = pos + substr(a[i], 2)
            printf "%c%c%c%c", v % 256, int(v / 256) % 256, int(v / 65536) % 256, int(v / 16777216) % 256
            pos += 4
        } else { printf "%c", a[i] + 0; pos++ }
    }
}
BEGIN { for (i = 32; i < 127; i++) ord[sprintf("%c", i)] = i }
'

# FBX 7.4 with a header extension, a Model and a Geometry connected to the root, whose Vertices are a
# zlib-encoded array of 2^28 - 1 doubles (2 GiB) in 8 compressed bytes (the zlib stream of nothing).
bomb_fbx() {
    LC_ALL=C awk "$HOSTILE_FBX_AWK"'
    END {
        head = str("Kaydara FBX Binary  ") " 0 26 0 " le(7400)
        hdr = rec("FBXHeaderExtension", 0, "", rec("FBXVersion", 1, pI(7400), ""))
        verts = rec("Vertices", 1, "100 " le(268435455) " " le(1) " " le(8) " 120 156 3 0 0 0 0 1", "")
        idx = rec("PolygonVertexIndex", 1, "105 " le(3) " " le(0) " " le(12) " " le(0) " " le(1) " " le(4294967293), "")
        geom = rec("Geometry", 3, pL(1) " " pS("g") " " pS("Mesh"), verts " " idx)
        model = rec("Model", 3, pL(2) " " pS("m") " " pS("Mesh"), rec("Version", 1, pI(232), ""))
        objects = rec("Objects", 0, "", geom " " model)
        conns = rec("Connections", 0, "", rec("C", 3, pS("OO") " " pL(1) " " pL(2), "") " " rec("C", 3, pS("OO") " " pL(2) " " pL(0), ""))
        emit(head " " hdr " " objects " " conns " " zeros(13))
    }' </dev/null >"$1"
}

# hostile_exr F B0 B1 B2 B3: a 32x16 OpenEXR capture (FLOAT B, G, R, no compression) whose every value is
# the little-endian float of those four bytes: 0 0 192 127 NaN, 0 0 128 127 +Inf, 0 0 128 191 -1,
# 0 0 0 0 zero, 194 22 1 0 a denormal (1e-40). For rouge-env's capture checks.
hostile_exr() {
    LC_ALL=C awk -v b0="$2" -v b1="$3" -v b2="$4" -v b3="$5" "$HOSTILE_FBX_AWK"'
    function attr(name, type, value) { return str(name) " 0 " str(type) " 0 " le(tlen(value)) " " value }
    function ch(name) { return str(name) " 0 " le(2) " 0 0 0 0 " le(1) " " le(1) }
    END {
        w = 32; h = 16
        box = le(0) " " le(0) " " le(w - 1) " " le(h - 1)
        head = "118 47 49 1 " le(2)
        head = head " " attr("channels", "chlist", ch("B") " " ch("G") " " ch("R") " 0")
        head = head " " attr("compression", "compression", "0") " " attr("dataWindow", "box2i", box)
        head = head " " attr("displayWindow", "box2i", box) " " attr("lineOrder", "lineOrder", "0")
        head = head " " attr("pixelAspectRatio", "float", "0 0 128 63") " " attr("screenWindowCenter", "v2f", zeros(8))
        head = head " " attr("screenWindowWidth", "float", "0 0 128 63") " 0"
        at = tlen(head) + 8 * h; line = 8 + w * 3 * 4
        table = ""
        for (y = 0; y < h; y++) table = table " " le(at + y * line) " 0 0 0 0"
        emit(head table)
        px = sprintf("%c%c%c%c", b0, b1, b2, b3)
        for (y = 0; y < h; y++) {
            emit(le(y) " " le(w * 12))
            for (i = 0; i < w * 3; i++) printf "%s", px
        }
    }' </dev/null >"$1"
}
