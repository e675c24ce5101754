// Seed pipeline: one point per triangle (pass 1) or per replica (pass 3); the geometry shader
// does the work, so the vertex only forwards its index.
flat out uint v_index;

void main() { v_index = uint(gl_VertexID); }
