// bumpbake's bump-mapping model for a GPU: the fragment stage of the course notes
// (shared/seeds). Lighting runs in tangent space: the normal comes straight from the normal map,
// decoded 2 * texel - 1 with x and y scaled by normalTexture.scale (glTF), and is lit with
// Blinn-Phong diffuse and specular terms against the interpolated, renormalised light and view
// directions. Spot lights cut off at their cone. Matches src/preview/shade.rs.
#version 330 core

const int MAX_LIGHTS = 8;

struct Light {
    vec4 position;
    vec3 spotDir;
    float cosCutOff;
    vec3 color;
};

in vec2 f_texCoord;
in vec3 f_viewDirection;
in vec3 f_lightDirection[MAX_LIGHTS];
in vec3 f_spotDirection[MAX_LIGHTS];

uniform sampler2D baseColorTexture; // sRGB texture format, so samples arrive linear
uniform sampler2D normalTexture;    // linear (UNORM) format: the texel is data, not colour
uniform vec4 baseColorFactor;
uniform float normalScale;          // normalTexture.scale
uniform float ambient;              // fraction of the base colour
uniform float specular;
uniform float shininess;
uniform int activeLights;
uniform Light lights[MAX_LIGHTS];

out vec4 fragColor; // write to an sRGB framebuffer (GL_FRAMEBUFFER_SRGB) for display

void main() {
    vec3 normal = 2.0 * texture(normalTexture, f_texCoord).rgb - 1.0;
    normal.xy *= normalScale;
    vec3 N = normalize(normal);
    vec3 V = normalize(f_viewDirection);
    vec4 base = baseColorFactor * texture(baseColorTexture, f_texCoord);

    vec3 color = ambient * base.rgb;
    for (int i = 0; i < MAX_LIGHTS; i++) {
        if (i >= activeLights) break;
        vec3 L = normalize(f_lightDirection[i]);
        if (lights[i].cosCutOff != 0.0 && dot(-L, normalize(f_spotDirection[i])) < lights[i].cosCutOff) continue;
        float diffuse = max(dot(N, L), 0.0);
        if (diffuse <= 0.0) continue;
        vec3 H = normalize(L + V);
        float spec = pow(max(dot(N, H), 0.0), shininess);
        color += lights[i].color * (base.rgb * diffuse + vec3(specular * spec));
    }
    fragColor = vec4(color, base.a);
}
