// bumpbake's bump-mapping model for a GPU: the vertex stage of the course notes
// (shared/seeds), written for glTF's attribute layout. `bumpbake preview` runs the same model on
// the CPU (src/preview/shade.rs); the two differ only in rasterisation details.
//
// Per vertex: N and T go to world space and are normalised, B = cross(N, T) * w (the TANGENT w
// of glTF, +1 or -1), and the directions to the eye, to every light and every spot axis are
// projected onto (T, B, N): moved into tangent space. They leave unnormalised, so that the
// interpolated vectors are exact for point lights; the fragment stage renormalises them.
#version 330 core

const int MAX_LIGHTS = 8;

struct Light {
    vec4 position;   // w == 0: directional, xyz = direction the light travels; w == 1: point/spot
    vec3 spotDir;    // axis of a spot light
    float cosCutOff; // 0 for point and directional lights, cos(half-angle) for a spot
    vec3 color;
};

layout(location = 0) in vec3 POSITION;
layout(location = 1) in vec3 NORMAL;
layout(location = 2) in vec4 TANGENT;   // xyz unit tangent, w = handedness (+1 or -1)
layout(location = 3) in vec2 TEXCOORD_0; // glTF convention: origin at the image's top-left

uniform mat4 modelMatrix;       // node's world transform
uniform mat3 normalMatrix;      // transpose(inverse(mat3(modelMatrix)))
uniform mat4 viewProjection;
uniform vec3 eyePosition;       // world space
uniform float mirrorSign;       // sign(determinant(mat3(modelMatrix))): mirrors flip w
uniform int activeLights;
uniform Light lights[MAX_LIGHTS];

out vec2 f_texCoord;
out vec3 f_viewDirection;              // tangent space, towards the eye
out vec3 f_lightDirection[MAX_LIGHTS]; // tangent space, towards each light
out vec3 f_spotDirection[MAX_LIGHTS];  // tangent space, spot axes

vec3 toTangent(vec3 v, vec3 t, vec3 b, vec3 n) {
    return vec3(dot(v, t), dot(v, b), dot(v, n));
}

void main() {
    vec4 world = modelMatrix * vec4(POSITION, 1.0);
    gl_Position = viewProjection * world;
    f_texCoord = TEXCOORD_0;

    vec3 n = normalize(normalMatrix * NORMAL);
    vec3 t = normalize(mat3(modelMatrix) * TANGENT.xyz);
    vec3 b = cross(n, t) * (TANGENT.w * mirrorSign);

    f_viewDirection = toTangent(eyePosition - world.xyz, t, b, n);
    for (int i = 0; i < MAX_LIGHTS; i++) {
        f_lightDirection[i] = vec3(0.0);
        f_spotDirection[i] = vec3(0.0);
        if (i >= activeLights) continue;
        vec3 toLight = lights[i].position.w == 0.0
            ? -lights[i].position.xyz
            : lights[i].position.xyz - world.xyz;
        f_lightDirection[i] = toTangent(toLight, t, b, n);
        if (lights[i].cosCutOff != 0.0) {
            f_spotDirection[i] = toTangent(lights[i].spotDir, t, b, n);
        }
    }
}
