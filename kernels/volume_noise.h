/* volume_noise.h — what shapes a volume's density (docs/volumetric.md §A volume): the per-ray
 * jitter hash, the noise texture's trilinear sample, the seed's shape + detail density field and
 * its fades. Needs volume_common.h. */

#ifndef VOL_LANE_INSTANCE /* the hash, the jitter and the texel load exist once */
/* PCG hash (Jarzynski & Olano, "Hash Functions for GPU Rendering", JCGT 2020): one 32-bit
 * state step and output permutation; integer arithmetic, the same bits in every path. */
#ifdef __OPENCL_C_VERSION__
static inline uint vol_hash(uint v) {
#else
inline std::uint32_t vol_hash(std::uint32_t v) {
#endif
  const VOL_UINT state = v * 747796405u + 2891336453u;
  const VOL_UINT word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

/* Per-ray jitter in [0, 1) from (target pixel, frame index): a new value every frame, so the
 * mean over frames converges to the unjittered high-step march. 24 bits: exact in float. */
#ifdef __OPENCL_C_VERSION__
static inline float vol_jitter(uint x, uint y, uint frame_index) {
#else
inline float vol_jitter(std::uint32_t x, std::uint32_t y, std::uint32_t frame_index) {
#endif
  const VOL_UINT h = vol_hash(x + vol_hash(y + vol_hash(frame_index)));
  return (float)(h >> 8) * 0x1p-24f;
}

/* The texture's texel (x, y, z) as four bytes 0..255 (docs/volumetric-noise.md: unorm8 RGBA,
 * x fastest). VOL_TEXEL_WORD_LOADS (GPUs, volume_march_options): one aligned 4-byte load, since
 * vload4 on a byte pointer may only assume byte alignment (the H100's physical march at 1080p:
 * 5.3 ms with vload4, 4.4 ms with this). CPU devices keep vload4: on PoCL 3.1 the word load made
 * the 1080p march 1.4x slower. Buffers are at least 4-byte aligned (CL_DEVICE_MEM_BASE_ADDR_ALIGN). */
#ifdef __OPENCL_C_VERSION__
#ifdef VOL_TEXEL_WORD_LOADS
#define VOL_TEXEL(tex, n, x, y, z) \
  convert_float4(((VOL_GLOBAL const uchar4*)(tex))[((size_t)(z) * (n) + (y)) * (n) + (x)])
#else
#define VOL_TEXEL(tex, n, x, y, z) convert_float4(vload4(((size_t)(z) * (n) + (y)) * (n) + (x), (tex)))
#endif
#else
#define VOL_TEXEL(tex, n, x, y, z) vol_texel<VOL_REAL>((tex), (n), (x), (y), (z))
template <typename VOL_REAL>
inline VOL_V4 vol_texel(const std::uint8_t* tex, int n, int x, int y, int z) {
  const std::uint8_t* t = tex + ((std::size_t(z) * n + y) * n + x) * 4;
  return VOL_V4(t[0], t[1], t[2], t[3]);
}
#endif
#endif /* VOL_LANE_INSTANCE */

/* a + (b - a) * f, and the same on each channel. */
VOL_FN VOL_REAL vol_lerp(VOL_REAL a, VOL_REAL b, VOL_REAL f) { return a + (b - a) * f; }
VOL_FN VOL_V4 vol_lerp4(VOL_V4 a, VOL_V4 b, VOL_REAL f) {
  return VOL_MAKE4(vol_lerp(a.x, b.x, f), vol_lerp(a.y, b.y, f), vol_lerp(a.z, b.z, f), vol_lerp(a.w, b.w, f));
}

/* The trilinear cell at uvw (texel centres at (i + 0.5) / N): the texels around it, wrapped, and
 * the weights *f. uvw is first wrapped to [0, 1), so far-away or late-in-time coordinates cost no
 * integer overflow. */
VOL_FN void vol_noise_cell(int n, VOL_V3 uvw, VOL_INT* x0, VOL_INT* x1, VOL_INT* y0, VOL_INT* y1, VOL_INT* z0,
                           VOL_INT* z1, VOL_V3* f) {
  const VOL_U fn = (VOL_U)n;
  const VOL_REAL gx = (uvw.x - floor(uvw.x)) * fn - (VOL_REAL)0.5f;
  const VOL_REAL gy = (uvw.y - floor(uvw.y)) * fn - (VOL_REAL)0.5f;
  const VOL_REAL gz = (uvw.z - floor(uvw.z)) * fn - (VOL_REAL)0.5f;
  const VOL_REAL gx0 = floor(gx), gy0 = floor(gy), gz0 = floor(gz);
  *f = VOL_MAKE3(gx - gx0, gy - gy0, gz - gz0);
  const int mask = n - 1; /* n is a power of two */
  *x0 = (VOL_TO_INT(gx0) + n) & mask;
  *y0 = (VOL_TO_INT(gy0) + n) & mask;
  *z0 = (VOL_TO_INT(gz0) + n) & mask;
  *x1 = (*x0 + 1) & mask;
  *y1 = (*y0 + 1) & mask;
  *z1 = (*z0 + 1) & mask;
}

/* Slice z of the cell: texels (x0, y), (x1, y) interpolated along x by fx for y0 and y1, then
 * along y by fy. The lanes instance loads each row's pair at once. */
#ifndef VOL_TEXEL_ROW
#define VOL_TEXEL_ROW(tex, n, x0, x1, y, z, fx) \
  vol_lerp4(VOL_TEXEL(tex, n, x0, y, z), VOL_TEXEL(tex, n, x1, y, z), (fx))
#endif
#define VOL_TEXEL_PLANE(tex, n, x0, x1, y0, y1, z, fx, fy) \
  vol_lerp4(VOL_TEXEL_ROW(tex, n, x0, x1, y0, z, fx), VOL_TEXEL_ROW(tex, n, x0, x1, y1, z, fx), (fy))

/* Trilinear sample with wrap-around at uvw, in [0, 1]: the manual filter of the buffer variant,
 * in the path's precision. */
VOL_FN VOL_V4 vol_noise_trilinear(VOL_GLOBAL const VOL_BYTE* tex, int n, VOL_V3 uvw) {
  VOL_INT x0, x1, y0, y1, z0, z1;
  VOL_V3 f;
  vol_noise_cell(n, uvw, &x0, &x1, &y0, &y1, &z0, &z1, &f);
  const VOL_V4 c = vol_lerp4(VOL_TEXEL_PLANE(tex, n, x0, x1, y0, y1, z0, f.x, f.y),
                             VOL_TEXEL_PLANE(tex, n, x0, x1, y0, y1, z1, f.x, f.y), f.z);
  return VOL_MAKE4(c.x / (VOL_REAL)255, c.y / (VOL_REAL)255, c.z / (VOL_REAL)255, c.w / (VOL_REAL)255);
}

/* Its R channel alone (the shape noise), the same arithmetic on that channel: where the includer
 * has planes of R alone (VOL_TEXEL_PLANE_R, the CPU lanes' 2 x 2 blocks of R) a slice is one load
 * per lane instead of two 8-byte ones. */
#ifdef VOL_TEXEL_PLANE_R
VOL_FN VOL_REAL vol_noise_trilinear_r(VOL_GLOBAL const VOL_BYTE* tex, int n, VOL_V3 uvw) {
  VOL_INT x0, x1, y0, y1, z0, z1;
  VOL_V3 f;
  vol_noise_cell(n, uvw, &x0, &x1, &y0, &y1, &z0, &z1, &f);
  return vol_lerp(VOL_TEXEL_PLANE_R(tex, n, x0, y0, z0, f.x, f.y), VOL_TEXEL_PLANE_R(tex, n, x0, y0, z1, f.x, f.y),
                  f.z) /
         (VOL_REAL)255;
}
#define VOL_NOISE_R(tex, n, uvw) vol_noise_trilinear_r((tex), (n), (uvw))
#endif

/* The includer may replace the sample (the image variant: the sampler's linear filter). */
#ifndef VOL_NOISE_SAMPLE
#define VOL_NOISE_SAMPLE(tex, n, uvw) vol_noise_trilinear((tex), (n), (uvw))
#endif
#ifndef VOL_NOISE_R
#define VOL_NOISE_R(tex, n, uvw) VOL_NOISE_SAMPLE(tex, n, uvw).x
#endif
#ifndef VOL_NOISE_PARAM
#define VOL_NOISE_PARAM VOL_GLOBAL const VOL_BYTE* noise
#endif

VOL_FN VOL_REAL vol_saturate(VOL_REAL x) { return fmin(fmax(x, (VOL_REAL)0), (VOL_REAL)1); }

/* x^e with the seed's default e = 1 exact (pow may round even then). */
VOL_FN VOL_REAL vol_pow(VOL_REAL x, VOL_U e) { return e == (VOL_U)1 ? x : pow(x, (VOL_REAL)e); }

/* The seed's density field in [0, 1] at world point p: shape noise (R) to fog_exponent, the
 * cut-off, then eroded by detail noise (R, B, A weighted 0.6 / 0.25 / 0.15; G is unused, as in
 * the seed). The cut-off remaps [cutoff, 1] to [0, 1]: the seed divides by (1 - fog) instead,
 * which saturates all noise above (1 + cutoff) / 2 and is singular at fog = 1 (a departure,
 * docs/volumetric.md §Departures from the seed). */
VOL_FN VOL_REAL vol_density_field(VOL_GLOBAL const float* vol, VOL_V3 p, VOL_U time, VOL_NOISE_PARAM,
                                  int noise_size, int detail) {
  const VOL_U3 speed = VOL_PU3(vol, VOL_V_SPEED), tiling = VOL_PU3(vol, VOL_V_TILING);
  const VOL_V3 uvw = VOL_MAKE3((p.x + speed.x * time) * tiling.x, (p.y + speed.y * time) * tiling.y,
                               (p.z + speed.z * time) * tiling.z);
  const VOL_U cutoff = VOL_PU(vol, VOL_V_FOG_CUTOFF);
  VOL_REAL fog = vol_pow(VOL_NOISE_R(noise, noise_size, uvw), VOL_PU(vol, VOL_V_FOG_EXPONENT));
  fog = vol_saturate((fog - cutoff) / ((VOL_U)1 - cutoff));
  if (detail) {
    const VOL_U strength = VOL_PU(vol, VOL_V_DETAIL_STRENGTH), e = VOL_PU(vol, VOL_V_DETAIL_EXPONENT);
    const VOL_U3 dt = VOL_PU3(vol, VOL_V_DETAIL_TILING);
    const VOL_U dtime = VOL_PU(vol, VOL_V_DETAIL_SPEED_MODIFIER) * time;
    const VOL_V3 duvw = VOL_MAKE3((p.x + speed.x * dtime) * dt.x, (p.y + speed.y * dtime) * dt.y,
                                  (p.z + speed.z * dtime) * dt.z);
    const VOL_V4 d = VOL_NOISE_SAMPLE(noise, noise_size, duvw);
    const VOL_REAL erosion = (VOL_REAL)0.6f * vol_pow(d.x, e) + (VOL_REAL)0.25f * vol_pow(d.z, e) +
                             (VOL_REAL)0.15f * vol_pow(d.w, e);
    fog = fog * ((VOL_U)1 - strength) + strength * erosion;
  }
  return fog;
}

/* 1 up to end - width, falling linearly to 0 at end. A width of 0 is a hard step at end, never a
 * division by zero (the seed divides by the width). */
VOL_FN VOL_REAL vol_fade_out(VOL_REAL x, VOL_U end, VOL_U width) {
  if (width > (VOL_U)0) return (VOL_REAL)1 - vol_saturate((x - (end - width)) / width);
  return x < end ? (VOL_REAL)1 : (VOL_REAL)0;
}

/* The seed's three fades at world point p, t along the ray from its origin: the edge fade inward
 * from the sphere's surface, the height fade below max_y, and the proximity fade, which thins fog
 * within proximity_fade of the camera (the seed measures t without its jitter and step rewind;
 * fogcl uses the sample's own t). */
VOL_FN VOL_REAL vol_fades(VOL_GLOBAL const float* vol, VOL_V3 p, VOL_REAL t) {
  const VOL_U3 c = VOL_PU3(vol, VOL_V_CENTER);
  const VOL_REAL dx = p.x - c.x, dy = p.y - c.y, dz = p.z - c.z;
  const VOL_REAL edge =
      vol_fade_out(sqrt(dx * dx + dy * dy + dz * dz), VOL_PU(vol, VOL_V_RADIUS), VOL_PU(vol, VOL_V_FADE_EDGE));
  const VOL_REAL height = vol_fade_out(p.y, VOL_PU(vol, VOL_V_MAX_Y), VOL_PU(vol, VOL_V_FADE_Y));
  const VOL_U proximity_width = VOL_PU(vol, VOL_V_PROXIMITY_FADE);
  const VOL_REAL proximity = proximity_width > (VOL_U)0 ? vol_saturate(t / proximity_width) : (VOL_REAL)1;
  return edge * height * proximity;
}
