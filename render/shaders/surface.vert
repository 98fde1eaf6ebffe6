// The surface's vertex shader: positions to view space, normals by the normal matrix, and each
// vertex's colour (a surface coloured by a second field) passed on.
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 colour_in;
uniform mat4 model_view;
uniform mat4 projection;
uniform mat3 normal_matrix;
out vec3 view_position;
out vec3 view_normal;
out vec3 vertex_colour;
void main() {
    vertex_colour = colour_in;
    vec4 p = model_view * vec4(position, 1.0);
    view_position = p.xyz;
    view_normal = normal_matrix * normal;
    gl_Position = projection * p;
}
