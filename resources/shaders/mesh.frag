#version 330 core
// Blinn-Phong with two coloured point lights plus ambient.

in vec3 v_world;
in vec3 v_normal;
in vec4 v_color;
in vec2 v_texcoord;

uniform vec3 u_eye;
uniform vec3 u_ambient;          // ambient light colour (times the material colour)
uniform vec3 u_light_pos[2];
uniform vec3 u_light_color[2];   // colour times intensity
uniform vec3 u_specular;         // specular colour of the material
uniform float u_shininess;
uniform int u_lit;               // 0: flat colour (grid, wireframe, gizmos)
uniform int u_faceted;           // 1: face normals from screen-space derivatives
uniform int u_two_sided;         // 1: light back faces with the flipped normal
uniform int u_textured;          // 1: the base colour times u_texture at v_texcoord
uniform sampler2D u_texture;

out vec4 frag_color;

void main() {
    if (u_lit == 0) {
        frag_color = v_color;
        return;
    }
    vec3 n;
    if (u_faceted == 1) {
        n = normalize(cross(dFdx(v_world), dFdy(v_world)));
    } else {
        n = normalize(v_normal);
        if (u_two_sided == 1 && !gl_FrontFacing) n = -n;
    }
    vec3 v = normalize(u_eye - v_world);
    if (u_faceted == 1 && dot(n, v) < 0.0) n = -n;
    vec3 base = v_color.rgb;
    if (u_textured == 1) base *= texture(u_texture, v_texcoord).rgb;
    vec3 colour = u_ambient * base;
    for (int i = 0; i < 2; ++i) {
        vec3 l = normalize(u_light_pos[i] - v_world);
        float diffuse = max(dot(n, l), 0.0);
        vec3 h = normalize(l + v);
        float spec = diffuse > 0.0 ? pow(max(dot(n, h), 0.0), u_shininess) : 0.0;
        colour += u_light_color[i] * (diffuse * base + spec * u_specular);
    }
    frag_color = vec4(colour, v_color.a);
}
