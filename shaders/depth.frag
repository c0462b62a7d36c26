#version 450
// Depth camera pass: the camera-frame depth Z of the nearest surface, metres. The clip-space w of
// mesh.vert is Z (see clip_from_projector), and gl_FragCoord.w = 1 / w is interpolated exactly.

layout(location = 0) out float out_depth;

void main() { out_depth = 1.0 / gl_FragCoord.w; }
