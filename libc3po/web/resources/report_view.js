const data = JSON.parse(document.getElementById('c3po-views').textContent);
const report = {views: data.views.length, webgl: false, frames: 0, shown: null, error: null};
window.c3poReport = report;

function decode(base64) {
  const binary = atob(base64);
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return new Float32Array(bytes.buffer);   // little-endian float32 xyz
}

// Test hook (report.measure = true): pixels of the last frame that differ
// from the background, read right after rendering.
function countColoured(gl) {
  const width = gl.drawingBufferWidth, height = gl.drawingBufferHeight;
  const pixels = new Uint8Array(width * height * 4);
  gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
  let count = 0;
  for (let i = 0; i < pixels.length; i += 4) {
    if (Math.abs(pixels[i] - 244) + Math.abs(pixels[i + 1] - 244) + Math.abs(pixels[i + 2] - 244) > 30) ++count;
  }
  return count;
}

const colours = {input: 0x1f5fd6, outliers: 0xe6194b, certified: 0x2e8b57, rejected: 0xd04040, truth: 0x888888,
                 rival: 0x17becf, keypoints: 0xf58231, detected: 0x911eb4};
const layerNames = ['truth', 'rival', 'posed', 'input', 'outliers', 'detected', 'keypoints'];

function makeViewer(THREE, box) {
  const renderer = new THREE.WebGLRenderer({antialias: true});
  renderer.setPixelRatio(window.devicePixelRatio);
  box.appendChild(renderer.domElement);
  const canvas = renderer.domElement;
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf4f4f4);
  const camera = new THREE.PerspectiveCamera(35, 1, 1e-3, 1e3);
  // three.js r111 (Debian libjs-three): legacy light units, 1/pi of the physical ones.
  scene.add(new THREE.HemisphereLight(0xffffff, 0x808080, 2.0 / Math.PI));
  const content = new THREE.Group();
  scene.add(content);
  const orbit = {theta: 0.6, phi: 1.1, distance: 1, target: new THREE.Vector3()};
  const layers = {};
  let pending = false;

  function draw() {
    pending = false;
    const width = Math.max(100, box.clientWidth), height = Math.max(100, box.clientHeight);
    renderer.setSize(width, height, false);
    canvas.style.width = width + 'px';
    canvas.style.height = height + 'px';
    camera.aspect = width / height;
    const s = Math.sin(orbit.phi);
    camera.position.set(orbit.target.x + orbit.distance * s * Math.sin(orbit.theta),
                        orbit.target.y + orbit.distance * Math.cos(orbit.phi),
                        orbit.target.z + orbit.distance * s * Math.cos(orbit.theta));
    camera.near = orbit.distance / 100;
    camera.far = orbit.distance * 100;
    camera.updateProjectionMatrix();
    camera.lookAt(orbit.target);
    renderer.render(scene, camera);
    if (report.measure) report.coloured = countColoured(renderer.getContext());
    report.frames += 1;
  }
  function request() {
    if (!pending) { pending = true; requestAnimationFrame(draw); }
  }

  function points(array, colour, size, opacity) {
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(array, 3));
    return new THREE.Points(geometry, new THREE.PointsMaterial(
        {color: colour, size: size, transparent: opacity < 1, opacity: opacity}));
  }
  function spheres(array, colour, radius) {
    const group = new THREE.Group();
    const geometry = new THREE.SphereGeometry(radius, 14, 10);
    const material = new THREE.MeshLambertMaterial({color: colour});
    for (let i = 0; i + 2 < array.length; i += 3) {
      const ball = new THREE.Mesh(geometry, material);
      ball.position.set(array[i], array[i + 1], array[i + 2]);
      group.add(ball);
    }
    return group;
  }
  function segments(from, to, colour) {
    const pairs = new Float32Array(from.length * 2);
    for (let i = 0; i + 2 < from.length && i + 2 < to.length; i += 3) {
      pairs.set(from.subarray(i, i + 3), 2 * i);
      pairs.set(to.subarray(i, i + 3), 2 * i + 3);
    }
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(pairs, 3));
    return new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({color: colour}));
  }

  function show(view) {
    for (const child of [...content.children]) content.remove(child);
    const input = decode(view.input), posed = decode(view.posed_model), truth = decode(view.truth_model);
    const keypoints = decode(view.keypoints), detected = decode(view.detected_keypoints);
    const box3 = new THREE.Box3().setFromBufferAttribute(new THREE.BufferAttribute(input.length ? input : posed, 3));
    const sphere = box3.getBoundingSphere(new THREE.Sphere());
    const radius = sphere.radius > 0 ? sphere.radius : 1;
    orbit.target.copy(sphere.center);
    orbit.distance = 3.2 * radius;
    const size = radius * 0.018;
    layers.truth = points(truth, colours.truth, size * 0.8, 0.35);
    layers.rival = points(decode(view.rival_model), colours.rival, size * 0.8, 0.55);
    layers.posed = points(posed, view.certified ? colours.certified : colours.rejected, size * 0.8, 0.55);
    layers.input = points(input, colours.input, size, 1);
    layers.outliers = points(decode(view.outliers), colours.outliers, size * 1.8, 1);
    layers.detected = new THREE.Group();
    if (detected.length) {
      layers.detected.add(spheres(detected, colours.detected, radius * 0.025));
      if (detected.length === keypoints.length) layers.detected.add(segments(detected, keypoints, colours.detected));
    }
    layers.keypoints = spheres(keypoints, colours.keypoints, radius * 0.03);
    for (const name of layerNames) {
      layers[name].visible = document.getElementById('layer-' + name).checked;
      content.add(layers[name]);
    }
    request();
  }

  // Orbit by drag, zoom by wheel.
  let drag = null;
  canvas.addEventListener('pointerdown', event => {
    drag = {x: event.clientX, y: event.clientY};
    canvas.setPointerCapture(event.pointerId);
  });
  canvas.addEventListener('pointermove', event => {
    if (!drag) return;
    orbit.theta -= (event.clientX - drag.x) * 0.008;
    orbit.phi = Math.min(Math.PI - 0.05, Math.max(0.05, orbit.phi - (event.clientY - drag.y) * 0.008));
    drag = {x: event.clientX, y: event.clientY};
    request();
  });
  canvas.addEventListener('pointerup', () => { drag = null; });
  canvas.addEventListener('wheel', event => {
    event.preventDefault();
    orbit.distance *= Math.exp(event.deltaY * 0.001);
    request();
  }, {passive: false});
  window.addEventListener('resize', request);
  for (const name of layerNames) {
    document.getElementById('layer-' + name).addEventListener('change', event => {
      if (layers[name]) { layers[name].visible = event.target.checked; request(); }
    });
  }
  return {show, orbit, request, canvas};
}

// Unknown numbers (no ground truth: a certify report) are null and left out.
function describe(view) {
  const info = document.getElementById('view-info');
  const parts = [(view.certified ? 'CERTIFIED' : 'not certified') + (view.false_certificate ? ' (FALSE CERTIFICATE)' : ''),
                 view.cloud];
  if (view.row) parts.push(view.row);
  if (view.adds !== null) parts.push('ADD-S ' + view.adds.toPrecision(3));
  if (view.rotation_error_deg !== null) parts.push('rotation error ' + view.rotation_error_deg.toFixed(1) + ' deg');
  if (view.truth_hausdorff !== null) parts.push('Hausdorff to the truth ' + view.truth_hausdorff.toPrecision(3));
  parts.push('oc distance ' + (view.oc_distance === null ? 'inf' : view.oc_distance.toPrecision(3)));
  if (view.refusal) parts.push('refused by ' + view.refusal);
  info.textContent = parts.join(' \u00b7 ');
}

async function start() {
  if (data.views.length === 0) return;
  const box = document.getElementById('view3d');
  const source = document.getElementById('c3po-three').textContent;
  const THREE = await import(URL.createObjectURL(new Blob([source], {type: 'text/javascript'})));
  let viewer;
  try {
    viewer = makeViewer(THREE, box);
  } catch (error) {
    box.textContent = '3D view unavailable (WebGL could not start): ' + error.message;
    return;
  }
  report.webgl = true;
  report.orbit = viewer.orbit;
  const buttons = document.getElementById('view-buttons');
  const select = i => {
    viewer.show(data.views[i]);
    describe(data.views[i]);
    report.shown = i;
    buttons.querySelectorAll('button').forEach((b, j) => b.classList.toggle('active', i === j));
  };
  report.show = select;
  data.views.forEach((view, i) => {
    const button = document.createElement('button');
    button.textContent = view.title;
    button.className = (view.certified ? 'certified' : 'rejected') + (view.false_certificate ? ' false-certificate' : '');
    button.addEventListener('click', () => select(i));
    buttons.appendChild(button);
  });
  select(0);
  await new Promise(resolve => requestAnimationFrame(() => requestAnimationFrame(resolve)));
}

try {
  await start();
} catch (error) {
  report.error = error.message;
  document.getElementById('view3d').textContent = '3D view unavailable: ' + error.message;
}
document.body.dataset.ready = '1';
