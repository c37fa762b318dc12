const data = JSON.parse(document.getElementById('c3po-data').textContent);
const object = data.object;
const notices = document.getElementById('notices');
function notice(text) {
  const item = document.createElement('li');
  item.textContent = text;
  notices.prepend(item);
}

// ---- state (the test hook reads window.c3poState) ----
const state = {
  keypoints: object.keypoints.map(p => p.slice()),
  keypoint_names: object.keypoints.map((_, i) => (object.keypoint_names || [])[i] || ''),
  indicator_sets: (object.indicator_sets || []).map(s => s.slice()),
};
window.c3poState = state;

function keypointLabel(i) { return i + ': ' + (state.keypoint_names[i] || 'kp' + i); }

// Same rule as `c3po annotate --remove I --drop-sets`: sets containing the
// removed keypoint are dropped, the other indices shift down.
function removeKeypoint(i) {
  const kept = [];
  for (const set of state.indicator_sets) {
    if (set.includes(i)) notice('dropped indicator set {' + set.join(',') + '}: it contained keypoint ' + i);
    else kept.push(set.map(j => (j > i ? j - 1 : j)));
  }
  state.indicator_sets = kept;
  state.keypoints.splice(i, 1);
  state.keypoint_names.splice(i, 1);
  refresh();
}

function addKeypoint(point) {
  state.keypoints.push([point.x, point.y, point.z]);
  state.keypoint_names.push('');
  refresh();
}

// The object JSON (schema of WriteObjectSpec).
function objectJson() {
  const out = {
    schema_version: object.schema_version, name: object.name, mesh: object.mesh,
    units: object.units, keypoints: state.keypoints,
  };
  if (state.keypoint_names.some(n => n)) out.keypoint_names = state.keypoint_names;
  out.indicator_sets = state.indicator_sets;
  out.eps_oc = object.eps_oc;
  out.delta_nd = object.delta_nd;
  if (object.extra !== undefined) out.extra = object.extra;
  return JSON.stringify(out, null, 2) + '\n';
}
window.c3poObjectJson = objectJson;

document.getElementById('download').addEventListener('click', () => {
  if (state.keypoints.length === 0) { notice('an object needs at least one keypoint'); return; }
  const link = document.createElement('a');
  link.href = URL.createObjectURL(new Blob([objectJson()], {type: 'application/json'}));
  link.download = object.name + '.json';
  document.body.appendChild(link);
  link.click();
  link.remove();
  setTimeout(() => URL.revokeObjectURL(link.href), 10000);
});

document.getElementById('title').textContent = object.name;
document.getElementById('info').textContent =
  'mesh ' + object.mesh + ' (' + data.triangle_count + ' triangles), units ' + object.units +
  ', diameter ' + data.diameter.toPrecision(4) + ', eps_oc ' + object.eps_oc.toPrecision(3) +
  ', delta_nd ' + object.delta_nd.toPrecision(3);

const palette = ['#e6194b', '#3cb44b', '#4363d8', '#f58231', '#911eb4', '#42d4f4',
                 '#f032e6', '#9a6324', '#469990', '#800000', '#000075', '#808000'];
const unsetColour = '#d00000';
function keypointColour(i) {
  const s = state.indicator_sets.findIndex(set => set.includes(i));
  return s >= 0 ? palette[s % palette.length] : unsetColour;
}

function rebuildPanel() {
  const n = state.keypoints.length;
  document.getElementById('count').textContent = n + (n === 1 ? ' keypoint' : ' keypoints');
  const list = document.getElementById('keypoint-list');
  list.replaceChildren();
  state.keypoints.forEach((p, i) => {
    const item = document.createElement('li');
    const swatch = document.createElement('span');
    swatch.className = 'swatch';
    swatch.style.background = keypointColour(i);
    const index = document.createElement('b');
    index.textContent = i;
    const name = document.createElement('input');
    name.value = state.keypoint_names[i];
    name.placeholder = 'kp' + i;
    name.addEventListener('change', () => { state.keypoint_names[i] = name.value.trim(); refresh(); });
    const coords = document.createElement('span');
    coords.className = 'coords';
    coords.textContent = p.map(v => v.toFixed(4)).join(', ');
    const remove = document.createElement('button');
    remove.textContent = '\u00d7';
    remove.title = 'remove keypoint ' + i;
    remove.addEventListener('click', () => removeKeypoint(i));
    item.append(swatch, index, name, coords, remove);
    list.append(item);
  });
  const legend = document.getElementById('legend');
  legend.replaceChildren();
  if (state.indicator_sets.length === 0) legend.textContent = 'none (non-degeneracy always holds)';
  state.indicator_sets.forEach((set, s) => {
    const row = document.createElement('div');
    const swatch = document.createElement('span');
    swatch.className = 'swatch';
    swatch.style.background = palette[s % palette.length];
    row.append(swatch, ' set ' + s + ': {' + set.join(', ') + '}');
    legend.append(row);
  });
  document.getElementById('download').disabled = n === 0;
}

// ---- 3D view ----
let view3d = null;
try {
  const source = document.getElementById('c3po-three').textContent;
  const THREE = await import(URL.createObjectURL(new Blob([source], {type: 'text/javascript'})));
  view3d = makeView(THREE);
} catch (error) {
  notice('3D view unavailable: ' + error.message);
}

function refresh() {
  rebuildPanel();
  if (view3d) view3d.rebuild();
}
refresh();
if (view3d) view3d.firstFrame.then(() => { document.body.dataset.ready = '1'; });
else document.body.dataset.ready = '1';

function decode(base64, Type) {
  const binary = atob(base64);
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return new Type(bytes.buffer);   // little-endian, like every browser platform
}

function makeView(THREE) {
  const box = document.getElementById('view');
  const labelBox = document.getElementById('labels');
  const renderer = new THREE.WebGLRenderer({antialias: true});
  renderer.setPixelRatio(window.devicePixelRatio);
  box.prepend(renderer.domElement);
  const canvas = renderer.domElement;

  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(decode(data.vertices_f32, Float32Array), 3));
  geometry.setIndex(new THREE.BufferAttribute(decode(data.triangles_u32, Uint32Array), 1));
  geometry.computeVertexNormals();
  geometry.computeBoundingBox();
  geometry.computeBoundingSphere();
  const diameter = data.diameter > 0 ? data.diameter : 1;
  const target = geometry.boundingBox.getCenter(new THREE.Vector3());

  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf4f4f4);
  const surface = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial(
      {color: 0xb4bccb, flatShading: true, side: THREE.DoubleSide, roughness: 0.85, metalness: 0}));
  scene.add(surface);
  const camera = new THREE.PerspectiveCamera(35, 1, diameter * 0.005, diameter * 200);
  // three.js r111 (Debian libjs-three): legacy light units, 1/pi of the physical ones.
  scene.add(new THREE.HemisphereLight(0xffffff, 0x707070, 1.6 / Math.PI));
  const headlight = new THREE.DirectionalLight(0xffffff, 1.6 / Math.PI);
  headlight.position.set(0.3, 0.5, 1);
  camera.add(headlight);
  scene.add(camera);

  const keypointGroup = new THREE.Group();
  scene.add(keypointGroup);
  const radius = diameter * 0.012;
  const sphere = new THREE.SphereGeometry(radius, 20, 14);

  // Orbit camera: spherical angles about `target`; the model's +z (robotics,
  // YCB) or +y (graphics, ShapeNet) axis points up on screen.
  const orbit = {theta: 0.7, phi: 1.1, distance: 2.2 * diameter, up: 'z'};
  function placeCamera() {
    const s = Math.sin(orbit.phi);
    const side = orbit.distance * s * Math.sin(orbit.theta);
    const up = orbit.distance * Math.cos(orbit.phi);
    const front = orbit.distance * s * Math.cos(orbit.theta);
    if (orbit.up === 'y') {
      camera.position.set(target.x + side, target.y + up, target.z + front);
      camera.up.set(0, 1, 0);
    } else {
      camera.position.set(target.x + side, target.y - front, target.z + up);
      camera.up.set(0, 0, 1);
    }
    camera.lookAt(target);
    camera.updateMatrixWorld();
  }
  const upButton = document.getElementById('up-axis');
  upButton.addEventListener('click', () => {
    orbit.up = orbit.up === 'z' ? 'y' : 'z';
    upButton.textContent = 'Up axis: ' + orbit.up.toUpperCase();
    requestRender();
  });
  function pan(dx, dy) {
    const scale = orbit.distance * Math.tan(camera.fov / 2 * Math.PI / 180) * 2 / canvas.clientHeight;
    const right = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 0);
    const up = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 1);
    target.addScaledVector(right, -dx * scale).addScaledVector(up, dy * scale);
  }

  let labels = [];
  let pending = false;
  let resolveFirst;
  const firstFrame = new Promise(resolve => { resolveFirst = resolve; });
  function requestRender() {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => {
      pending = false;
      placeCamera();
      renderer.render(scene, camera);
      updateLabels();
      resolveFirst();
      clearTimeout(occlusionTimer);
      occlusionTimer = setTimeout(markHiddenLabels, 150);
    });
  }
  // Labels of keypoints behind the surface are dimmed (once the view is still).
  let occlusionTimer = 0;
  function markHiddenLabels() {
    const ray = new THREE.Raycaster();
    state.keypoints.forEach((p, i) => {
      if (!labels[i]) return;
      const point = new THREE.Vector3(p[0], p[1], p[2]);
      const toPoint = point.clone().sub(camera.position);
      const distance = toPoint.length();
      ray.set(camera.position, toPoint.normalize());
      ray.far = distance - radius;
      labels[i].classList.toggle('hidden-behind', ray.intersectObject(surface, false).length > 0);
    });
  }
  function toPixel(p) {
    const v = new THREE.Vector3(p[0], p[1], p[2]).project(camera);
    return {x: (v.x + 1) / 2 * canvas.clientWidth, y: (1 - v.y) / 2 * canvas.clientHeight, front: v.z < 1};
  }
  function updateLabels() {
    state.keypoints.forEach((p, i) => {
      const pixel = toPixel(p);
      labels[i].style.display = pixel.front ? '' : 'none';
      labels[i].style.left = pixel.x + 'px';
      labels[i].style.top = pixel.y + 'px';
    });
  }
  function rebuild() {
    for (const child of keypointGroup.children) child.material.dispose();
    while (keypointGroup.children.length) keypointGroup.remove(keypointGroup.children[0]);   // Object3D.clear() is r123+
    labelBox.replaceChildren();
    labels = state.keypoints.map((p, i) => {
      const marker = new THREE.Mesh(sphere, new THREE.MeshStandardMaterial({color: keypointColour(i)}));
      marker.position.set(p[0], p[1], p[2]);
      marker.userData.index = i;
      keypointGroup.add(marker);
      const label = document.createElement('div');
      label.className = 'label';
      label.textContent = keypointLabel(i);
      label.style.color = keypointColour(i);
      labelBox.append(label);
      return label;
    });
    requestRender();
  }
  function resize() {
    renderer.setSize(box.clientWidth, box.clientHeight);
    camera.aspect = box.clientWidth / Math.max(1, box.clientHeight);
    camera.updateProjectionMatrix();
    requestRender();
  }
  window.addEventListener('resize', resize);
  resize();

  // What a click at canvas pixel (x, y) does: remove the keypoint hit first
  // (unless the surface is clearly in front of it), else add the surface point.
  const raycaster = new THREE.Raycaster();
  function pickAt(x, y) {
    placeCamera();
    const ndc = new THREE.Vector2(x / canvas.clientWidth * 2 - 1, -(y / canvas.clientHeight) * 2 + 1);
    raycaster.setFromCamera(ndc, camera);
    const marker = raycaster.intersectObjects(keypointGroup.children, false)[0];
    const hit = raycaster.intersectObject(surface, false)[0];
    if (marker && (!hit || marker.distance <= hit.distance + radius)) {
      return {remove: marker.object.userData.index};
    }
    if (hit) return {add: hit.point};
    return {};
  }
  function click(x, y) {
    const action = pickAt(x, y);
    if (action.remove !== undefined) removeKeypoint(action.remove);
    else if (action.add) addKeypoint(action.add);
  }

  let drag = null;
  canvas.addEventListener('pointerdown', e => {
    drag = {x: e.clientX, y: e.clientY, lastX: e.clientX, lastY: e.clientY,
            button: e.button, pan: e.button === 2 || e.shiftKey, moved: false};
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener('pointermove', e => {
    if (!drag) return;
    const dx = e.clientX - drag.lastX, dy = e.clientY - drag.lastY;
    drag.lastX = e.clientX;
    drag.lastY = e.clientY;
    if (Math.hypot(e.clientX - drag.x, e.clientY - drag.y) > 4) drag.moved = true;
    if (!drag.moved) return;
    if (drag.pan) {
      pan(dx, dy);
    } else {
      orbit.theta -= dx * 0.008;
      orbit.phi = Math.min(Math.PI - 0.05, Math.max(0.05, orbit.phi - dy * 0.008));
    }
    requestRender();
  });
  canvas.addEventListener('pointerup', e => {
    const d = drag;
    drag = null;
    if (d && !d.moved && d.button === 0 && !d.pan) {
      const rect = canvas.getBoundingClientRect();
      click(e.clientX - rect.left, e.clientY - rect.top);
    }
  });
  canvas.addEventListener('contextmenu', e => e.preventDefault());
  canvas.addEventListener('wheel', e => {
    e.preventDefault();
    orbit.distance = Math.min(50 * diameter, Math.max(0.05 * diameter, orbit.distance * Math.exp(e.deltaY * 0.001)));
    requestRender();
  }, {passive: false});

  // Test hooks: page pixels where a scripted click removes keypoint i, or
  // lands on the surface away from every keypoint.
  window.c3poDebug = {
    keypointPixel(i) {
      const rect = canvas.getBoundingClientRect();
      const p = toPixel(state.keypoints[i]);
      const visible = p.front && pickAt(p.x, p.y).remove === i;
      return {x: rect.left + p.x, y: rect.top + p.y, visible};
    },
    meshPixel() {
      const rect = canvas.getBoundingClientRect();
      const w = canvas.clientWidth, h = canvas.clientHeight;
      const far = 6 * radius;
      for (let ring = 0; ring < Math.max(w, h) / 2; ring += 6) {
        for (let a = 0; a < 16; ++a) {
          const x = w / 2 + ring * Math.cos(a * Math.PI / 8), y = h / 2 + ring * Math.sin(a * Math.PI / 8);
          if (x < 0 || y < 0 || x >= w || y >= h) continue;
          const action = pickAt(x, y);
          if (!action.add) continue;
          if (state.keypoints.every(p => Math.hypot(p[0] - action.add.x, p[1] - action.add.y, p[2] - action.add.z) > far)) {
            return {x: rect.left + x, y: rect.top + y};
          }
        }
      }
      return null;
    },
  };
  return {rebuild, firstFrame};
}
