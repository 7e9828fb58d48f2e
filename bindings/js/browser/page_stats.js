// Runs inside the page (passed to page.evaluate): the share of canvas pixels
// that differ from the background and their mean colour (0..1 per channel).
export async function canvasStats() {
  const canvas = document.querySelector('#view canvas');
  const img = new Image();
  img.src = canvas.toDataURL('image/png');
  await img.decode();
  const c = document.createElement('canvas');
  c.width = img.width;
  c.height = img.height;
  const ctx = c.getContext('2d');
  ctx.drawImage(img, 0, 0);
  const d = ctx.getImageData(0, 0, c.width, c.height).data;
  const bg = [0x10, 0x14, 0x18];
  let n = 0;
  const sum = [0, 0, 0];
  for (let i = 0; i < d.length; i += 4) {
    if (Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]) > 12) {
      n++;
      for (let k = 0; k < 3; k++) sum[k] += d[i + k];
    }
  }
  return { share: n / (d.length / 4), mean: sum.map((s) => (n ? s / n / 255 : 0)) };
}
