#version 300 es
// irradiance.frag.glsl — never runs (the irradiance pass discards rasterisation); GLSL ES needs one to link.
precision mediump float;
void main() {}
