// Tessellator form, vertex stage: one patch of one vertex per list triangle; the control stage
// does the work, so the vertex forwards its triangle and the instance (see tess_replicas.tesc).
flat out uint v_index;
flat out uint v_instance;

void main() {
  v_index = uint(gl_VertexID);
  v_instance = uint(gl_InstanceID);
}
