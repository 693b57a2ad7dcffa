// report.html's 3-D view: the map's mesh (or points) and the camera paths (three.js), turned with the
// mouse (three.js' OrbitControls). The data come from <script id="map-3d-data"> (map z up, metres);
// when the view is drawn, <html data-scene> says "ok ..." (a test reads it).
"use strict";
(function () {
  const root = document.documentElement;
  const canvas = document.getElementById("map-3d-canvas");
  const data = JSON.parse(document.getElementById("map-3d-data").textContent);

  function bytes(text) {
    const binary = atob(text);
    const out = new Uint8Array(binary.length);
    for (let i = 0; i < binary.length; ++i) out[i] = binary.charCodeAt(i);
    return out;
  }

  // 16-bit positions within [min, max] per axis, back to metres.
  function positions() {
    const quantised = new Uint16Array(bytes(data.positions).buffer);
    const out = new Float32Array(quantised.length);
    for (let i = 0; i < quantised.length; ++i) {
      const a = i % 3;
      out[i] = data.min[a] + (data.max[a] - data.min[a]) * quantised[i] / 65535;
    }
    return out;
  }

  // The map's colours, or grey by height where it has none.
  function colours(xyz) {
    if (data.colours.length > 0) return new THREE.BufferAttribute(bytes(data.colours), 3, true);
    const out = new Float32Array(xyz.length);
    const span = Math.max(1e-6, data.ceiling_z - data.min[2]);
    for (let i = 0; i < xyz.length; i += 3)
      out[i] = out[i + 1] = out[i + 2] = 0.3 + 0.6 * Math.min(1, (xyz[i + 2] - data.min[2]) / span);
    return new THREE.BufferAttribute(out, 3);
  }

  function path(coordinates, colour) {
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute("position", new THREE.Float32BufferAttribute(coordinates, 3));
    return new THREE.Line(geometry, new THREE.LineBasicMaterial({color: colour}));
  }

  function pointCloud(ceiling) {
    const xyz = positions();
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute("position", new THREE.BufferAttribute(xyz, 3));
    geometry.setAttribute("color", colours(xyz));
    const material = new THREE.PointsMaterial({
      size: data.point_size, vertexColors: THREE.VertexColors, clippingPlanes: [ceiling]});
    return new THREE.Points(geometry, material);
  }

  // The TSDF's surface: vertex colours, lit from above so that its shape shows.
  function surface(ceiling) {
    const geometry = new THREE.BufferGeometry();
    const xyz = positions();
    geometry.setAttribute("position", new THREE.BufferAttribute(xyz, 3));
    geometry.setAttribute("color", colours(xyz));
    geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(bytes(data.triangles).buffer), 1));
    geometry.computeVertexNormals();
    const material = new THREE.MeshLambertMaterial({
      vertexColors: THREE.VertexColors, side: THREE.DoubleSide, clippingPlanes: [ceiling]});
    return new THREE.Mesh(geometry, material);
  }

  // Looks at the map's middle from `direction` (map frame), far enough to see all of it.
  function viewFrom(camera, controls, direction) {
    const low = new THREE.Vector3().fromArray(data.min);
    const high = new THREE.Vector3().fromArray(data.max);
    high.z = Math.min(high.z, data.ceiling_z);
    const centre = low.clone().add(high).multiplyScalar(0.5);
    const radius = Math.max(0.5, low.distanceTo(high) / 2);
    const distance = 0.8 * radius / Math.sin(camera.fov * Math.PI / 360);  // the map fills the view
    camera.position.copy(centre).add(direction.clone().normalize().multiplyScalar(distance));
    controls.target.copy(centre);
    controls.update();
  }

  function build() {
    const renderer = new THREE.WebGLRenderer({canvas: canvas, antialias: true,
                                              preserveDrawingBuffer: true});
    renderer.setPixelRatio(window.devicePixelRatio);
    renderer.setClearColor(0x1d2230);
    renderer.localClippingEnabled = true;
    const scene = new THREE.Scene();
    const ceiling = new THREE.Plane(new THREE.Vector3(0, 0, -1), data.ceiling_z);  // keeps z below
    if (data.triangles) {
      scene.add(surface(ceiling));
      scene.add(new THREE.AmbientLight(0xffffff, 0.55));
      const light = new THREE.DirectionalLight(0xffffff, 0.6);
      light.position.set(0.3, -0.5, 1);
      scene.add(light);
    } else {
      scene.add(pointCloud(ceiling));
    }
    if (data.truth.length > 0) scene.add(path(data.truth, 0xffc800));
    scene.add(path(data.estimated, 0xff3b30));
    const reach = Math.ceil(Math.max(Math.abs(data.min[0]), Math.abs(data.max[0]),
                                     Math.abs(data.min[1]), Math.abs(data.max[1])));
    const grid = new THREE.GridHelper(2 * reach, 2 * reach, 0x556070, 0x394050);  // 1 m cells
    grid.rotation.x = Math.PI / 2;  // the helper lies in x-z; the floor is x-y
    scene.add(grid);

    const camera = new THREE.PerspectiveCamera(45, 1, 0.02, 1000);
    camera.up.set(0, 0, 1);
    const controls = new THREE.OrbitControls(camera, canvas);
    const render = function () { renderer.render(scene, camera); };
    const resize = function () {
      renderer.setSize(canvas.clientWidth, canvas.clientHeight, false);
      camera.aspect = canvas.clientWidth / Math.max(1, canvas.clientHeight);
      camera.updateProjectionMatrix();
      render();
    };
    controls.addEventListener("change", render);
    window.addEventListener("resize", resize);
    const views = {oblique: new THREE.Vector3(-0.55, -0.8, 0.75), above: new THREE.Vector3(0, -0.001, 1)};
    for (const button of document.querySelectorAll("[data-view]"))
      button.addEventListener("click", function () {
        viewFrom(camera, controls, views[button.getAttribute("data-view")]);
      });
    document.getElementById("map-3d-ceiling").addEventListener("change", function (event) {
      ceiling.constant = event.target.checked ? 1e9 : data.ceiling_z;
      render();
    });
    viewFrom(camera, controls, views.oblique);
    resize();
    const drawn = data.triangles ? data.triangle_count + " triangles, " : data.count + " points, ";
    root.setAttribute("data-scene", "ok " + drawn + data.estimated.length / 3 + " poses");
  }

  try {
    build();
  } catch (error) {
    const message = document.getElementById("map-3d-message");
    message.textContent = "The 3-D view needs WebGL: " + error.message;
    message.hidden = false;
    root.setAttribute("data-scene", "failed: " + error.message);
    throw error;
  }
})();
