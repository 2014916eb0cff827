#version 330 core
// One vertex shader for every lit object: static meshes, instanced primitives
// (skeleton boxes, spheres, bone cylinders) and GPU-skinned meshes.
//
// Skinning: joint matrices M_j = W_j * inverse(B_j) live in a texture buffer
// (4 RGBA32F texels per joint, one per column). Each vertex has a list of
// (joint, weight) pairs in another texture buffer (RG32F), addressed by the
// attribute a_influence = (first, count), so any number of influences works.

layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_color;
layout(location = 3) in vec2 a_influence;
layout(location = 4) in vec4 a_model0;   // per-instance model matrix columns
layout(location = 5) in vec4 a_model1;
layout(location = 6) in vec4 a_model2;
layout(location = 7) in vec4 a_model3;
layout(location = 8) in vec4 a_icolor;   // per-instance colour
layout(location = 9) in vec2 a_texcoord; // texture coordinates (t = 0 at the image's top)

uniform mat4 u_model;
uniform mat4 u_view;
uniform mat4 u_proj;
uniform int u_instanced;        // 1: use the per-instance model matrix and colour
uniform int u_use_vertex_color; // 1: a_color, else u_color
uniform vec4 u_color;
uniform int u_skinning;         // 1: blend joint matrices
uniform samplerBuffer u_joint_tex;
uniform samplerBuffer u_influence_tex;
uniform int u_weight_mode;      // -2: off, -1: all joints pseudo-colour, >=0: that joint's weight

out vec3 v_world;
out vec3 v_normal;
out vec4 v_color;
out vec2 v_texcoord;

mat4 joint_matrix(int j) {
    return mat4(texelFetch(u_joint_tex, 4 * j), texelFetch(u_joint_tex, 4 * j + 1),
                texelFetch(u_joint_tex, 4 * j + 2), texelFetch(u_joint_tex, 4 * j + 3));
}

vec3 joint_colour(int j) {
    // well separated hues from the golden ratio
    float h = fract(float(j) * 0.618034 + 0.1);
    vec3 k = clamp(abs(mod(h * 6.0 + vec3(0.0, 4.0, 2.0), 6.0) - 3.0) - 1.0, 0.0, 1.0);
    return mix(vec3(1.0), k, 0.85);
}

// Normals transform by the inverse transpose; the cofactor matrix det(A)·A⁻ᵀ is the same up
// to scale and much cheaper per vertex (the sign fixes mirroring matrices).
vec3 normal_transform(mat3 a, vec3 n) {
    mat3 cof = mat3(cross(a[1], a[2]), cross(a[2], a[0]), cross(a[0], a[1]));
    float det = dot(a[0], cof[0]);
    return (det < 0.0 ? -1.0 : 1.0) * (cof * n);
}

vec3 heat(float w) {
    return clamp(vec3(1.5 * w, 1.5 - abs(2.0 * w - 1.0) * 1.5, 1.5 * (1.0 - w)), 0.0, 1.0);
}

void main() {
    mat4 model = u_model;
    vec4 colour = u_use_vertex_color == 1 ? a_color : u_color;
    if (u_instanced == 1) {
        model = model * mat4(a_model0, a_model1, a_model2, a_model3);
        colour = a_icolor;
    }
    vec4 p = vec4(a_position, 1.0);
    vec3 n = a_normal;
    if (u_skinning == 1) {
        mat4 m = mat4(0.0);
        int first = int(a_influence.x + 0.5);
        int count = int(a_influence.y + 0.5);
        vec3 tint = vec3(0.0);
        float picked = 0.0;
        for (int i = 0; i < count; ++i) {
            vec2 jw = texelFetch(u_influence_tex, first + i).xy;
            int j = int(jw.x + 0.5);
            m += jw.y * joint_matrix(j);
            tint += jw.y * joint_colour(j);
            if (j == u_weight_mode) picked += jw.y;
        }
        p = m * p;
        n = normal_transform(mat3(m), n);
        if (u_weight_mode == -1) colour = vec4(tint, 1.0);
        else if (u_weight_mode >= 0) colour = vec4(heat(picked), 1.0);
    }
    vec4 world = model * p;
    v_world = world.xyz;
    v_normal = normal_transform(mat3(model), n);
    v_color = colour;
    v_texcoord = a_texcoord;
    gl_Position = u_proj * u_view * world;
}
