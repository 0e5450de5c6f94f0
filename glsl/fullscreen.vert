// fullscreen.vert: one triangle that covers the whole viewport, from gl_VertexID alone
// (no vertex buffer), so the fragment shader runs exactly once per pixel.
void main()
{
    vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
