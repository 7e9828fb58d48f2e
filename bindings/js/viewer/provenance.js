// The frame provenance of a map (spec/format.md section 2.3): `map_frames`,
// one line per inserted frame: index n_points n_novel, the first three rows
// of the camera-to-world pose, and the map's component count after the
// frame (absent in older files).

/** [{index, nPoints, nNovel, pose: 16 row-major, nComponents|null}] or [] when absent or malformed. */
export function parseMapFrames(text) {
  if (typeof text !== 'string' || text === '') return [];
  const frames = [];
  for (const line of text.split('\n')) {
    if (line === '') continue;
    const f = line.split(' ').map(Number);
    if ((f.length !== 15 && f.length !== 16) || !f.every(Number.isFinite) || f[0] !== frames.length) return [];
    frames.push({
      index: f[0], nPoints: f[1], nNovel: f[2],
      pose: [...f.slice(3, 15), 0, 0, 0, 1],
      nComponents: f.length === 16 ? f[15] : null,
    });
  }
  return frames;
}
