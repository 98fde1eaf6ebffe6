// Headlight Phong: the light sits at the eye, so the light and view directions coincide and the
// half vector is the light direction itself. Back faces (seen through holes in an open surface)
// get their normal flipped and a cooler colour, so inside and outside are told apart. A mesh with
// colours (coloured by a second field) takes its vertex colour in front and a darker one behind.
// render/headlight.h computes the same colours in C++ (tests/renderer_test.cpp draws both).
in vec3 view_position;
in vec3 view_normal;
in vec3 vertex_colour;
uniform bool orthographic;
uniform bool coloured;
out vec4 colour;
const vec3 kFrontColour = vec3(0.9, 0.85, 0.75);
const vec3 kBackColour = vec3(0.6, 0.68, 0.85);
const float kAmbient = 0.08;
const float kDiffuse = 0.85;
const float kSpecular = 0.25;
const float kShininess = 40.0;
void main() {
    vec3 n = normalize(view_normal);
    vec3 base = coloured ? vertex_colour : kFrontColour;
    if (!gl_FrontFacing) {
        n = -n;
        base = coloured ? 0.6 * vertex_colour : kBackColour;
    }
    // An orthographic eye is at infinity along +z of view space.
    vec3 to_light = orthographic ? vec3(0.0, 0.0, 1.0) : normalize(-view_position);
    float lambert = max(dot(n, to_light), 0.0);
    float highlight = kSpecular * pow(lambert, kShininess);
    colour = vec4(base * (kAmbient + kDiffuse * lambert) + vec3(highlight), 1.0);
}
