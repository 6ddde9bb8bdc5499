// Counts the pixels of a viewer screenshot dominated by each texel colour of make_textured_box.py's
// texture (red, green, blue): the untextured faces are orange and grey, so green- and blue-dominated
// pixels come from the texture alone. Exit 1 unless each of the three covers at least 0.05 % of the
// picture.
// usage: node tests/looks/texels.js SCREENSHOT.png
'use strict';
const fs = require('fs');
const { decodePNG } = require('../web/png.js');

const img = decodePNG(fs.readFileSync(process.argv[2]));
const counts = { red: 0, green: 0, blue: 0 };
const n = img.width * img.height;
for (let i = 0; i < n; ++i) {
  const r = img.data[i * img.channels], g = img.data[i * img.channels + 1], b = img.data[i * img.channels + 2];
  if (r > 40 && r > 4 * g && r > 4 * b) counts.red++;
  if (g > 40 && g > 2 * r && g > 2 * b) counts.green++;
  if (b > 40 && b > 2 * r && b > 2 * g) counts.blue++;
}
const share = (c) => (100 * c / n).toFixed(3);
console.log(`texels.js: ${process.argv[2]}: red ${share(counts.red)} %, green ${share(counts.green)} %, blue ${share(counts.blue)} %`);
process.exit(Object.values(counts).every((c) => c >= 0.0005 * n) ? 0 : 1);
