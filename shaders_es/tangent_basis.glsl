// tangent_basis.glsl — an orthonormal basis around a unit vector n (Duff et al. 2017, "Building an
// Orthonormal Basis, Revisited"), the same as splat.c's tangents_of: the bent normal's bits are a turn
// along it, and the attribute pass carries the bent normal as its components along it. Continuous
// everywhere but n = -z (in view space: a surface facing straight away, never drawn).
void rs_tangents(vec3 n, out vec3 t1, out vec3 t2)
{
    float s = n.z < 0.0 ? -1.0 : 1.0, a = -1.0 / (s + n.z), b = n.x * n.y * a;
    t1 = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    t2 = vec3(b, s + n.y * n.y * a, -n.y);
}
