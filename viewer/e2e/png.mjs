// A small PNG decoder (8-bit greyscale, RGB or RGBA, not interlaced: what Chromium's screenshots
// are) so the e2e test can count differing pixels with no dependency. Returns {width, height, rgba}.
import { inflateSync } from 'node:zlib';

export function decodePng(buf) {
  const signature = [137, 80, 78, 71, 13, 10, 26, 10];
  signature.forEach((b, i) => {
    if (buf[i] !== b) throw new Error('not a PNG');
  });
  let o = 8;
  let width = 0, height = 0, depth = 0, type = 0, interlace = 0;
  const idat = [];
  while (o < buf.length) {
    const len = buf.readUInt32BE(o);
    const name = buf.toString('latin1', o + 4, o + 8);
    const data = buf.subarray(o + 8, o + 8 + len);
    if (name === 'IHDR') {
      width = data.readUInt32BE(0);
      height = data.readUInt32BE(4);
      depth = data[8];
      type = data[9];
      interlace = data[12];
    } else if (name === 'IDAT') idat.push(data);
    else if (name === 'IEND') break;
    o += 12 + len;
  }
  const channels = { 0: 1, 2: 3, 4: 2, 6: 4 }[type];
  if (depth !== 8 || !channels || interlace) throw new Error(`unsupported PNG (depth ${depth}, colour type ${type}, interlace ${interlace})`);
  const raw = inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const out = Buffer.alloc(stride * height);
  for (let y = 0; y < height; y++) {
    const filter = raw[y * (stride + 1)];
    const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    const cur = out.subarray(y * stride, (y + 1) * stride);
    const prev = y ? out.subarray((y - 1) * stride, y * stride) : null;
    for (let x = 0; x < stride; x++) {
      const a = x >= channels ? cur[x - channels] : 0;
      const b = prev ? prev[x] : 0;
      const c = prev && x >= channels ? prev[x - channels] : 0;
      let v = line[x];
      if (filter === 1) v += a;
      else if (filter === 2) v += b;
      else if (filter === 3) v += (a + b) >> 1;
      else if (filter === 4) {
        const p = a + b - c, pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
        v += pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      } else if (filter !== 0) throw new Error(`bad PNG filter ${filter}`);
      cur[x] = v & 255;
    }
  }
  const rgba = Buffer.alloc(width * height * 4);
  for (let k = 0; k < width * height; k++) {
    const s = out.subarray(k * channels, (k + 1) * channels);
    if (channels >= 3) { rgba[4 * k] = s[0]; rgba[4 * k + 1] = s[1]; rgba[4 * k + 2] = s[2]; }
    else rgba[4 * k] = rgba[4 * k + 1] = rgba[4 * k + 2] = s[0];
    rgba[4 * k + 3] = channels === 4 ? s[3] : channels === 2 ? s[1] : 255;
  }
  return { width, height, rgba };
}

/** Pixels whose largest channel difference exceeds `threshold` (0..255). */
export function differingPixels(a, b, threshold = 32) {
  if (a.width !== b.width || a.height !== b.height) throw new Error('screenshots differ in size');
  let n = 0;
  for (let k = 0; k < a.width * a.height; k++) {
    const d = Math.max(
      Math.abs(a.rgba[4 * k] - b.rgba[4 * k]),
      Math.abs(a.rgba[4 * k + 1] - b.rgba[4 * k + 1]),
      Math.abs(a.rgba[4 * k + 2] - b.rgba[4 * k + 2]),
    );
    if (d > threshold) n++;
  }
  return n;
}
