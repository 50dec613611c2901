// redres view: the 3-D replay of finished runs (docs/viewer.md). The page's data (the runs' frames, shapes,
// obstacles and plotted series) is the JSON in #redres-data, written by redres (framework/src/run/view.cpp);
// three.js and its orbit controls are inlined before this script. No network access: everything is in the file.
(function () {
  'use strict';
  var scriptStartMs = performance.now();

  // ---- errors are kept, so that a test (and the status line) can see them ----
  var errors = [];
  window.addEventListener('error', function (e) { errors.push(String(e.message || e)); });
  window.addEventListener('unhandledrejection', function (e) { errors.push('unhandled rejection: ' + e.reason); });
  var consoleError = console.error;
  console.error = function () {
    errors.push(Array.prototype.map.call(arguments, String).join(' '));
    consoleError.apply(console, arguments);
  };

  var data = JSON.parse(document.getElementById('redres-data').textContent);
  var runs = data.runs;
  var RUN_COLOURS = ['#2f6db5', '#d9702b', '#2f9a4a', '#8e44ad', '#c0392b', '#138d75', '#7f8c8d', '#b7950b'];
  var JOINT_COLOURS = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2', '#7f7f7f',
                       '#bcbd22', '#17becf'];
  var hash = window.location.hash.replace(/^#/, '');
  var params = {};
  hash.split('&').forEach(function (kv) {
    if (!kv) return;
    var i = kv.indexOf('=');
    params[i < 0 ? kv : kv.slice(0, i)] = i < 0 ? '' : decodeURIComponent(kv.slice(i + 1));
  });

  document.getElementById('title').textContent = data.title;
  document.title = data.title + ' - redres view';

  // ---- the timeline: the frames of the run with the most of them ----
  var main = 0;
  runs.forEach(function (r, i) { if (r.frames.t.length > runs[main].frames.t.length) main = i; });
  var timeline = runs[main].frames.t;
  var tEnd = 0;
  runs.forEach(function (r) { tEnd = Math.max(tEnd, r.frames.t[r.frames.t.length - 1]); });

  // ---- the 3-D scene (z up, as the robots' frames) ----
  THREE.Object3D.DefaultUp.set(0, 0, 1);
  var sceneBox = document.getElementById('scene');
  var renderer;
  try {
    renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  } catch (e) {
    errors.push('WebGL is not available: ' + e.message);
    document.getElementById('status').textContent = 'WebGL is not available in this browser: ' + e.message;
    return;
  }
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  sceneBox.appendChild(renderer.domElement);
  var scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf4f5f7);
  var camera = new THREE.PerspectiveCamera(40, 1, 0.005, 200);
  var controls = new THREE.OrbitControls(camera, renderer.domElement);
  controls.enableDamping = false;
  controls.screenSpacePanning = true;
  scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8f99, 0.85));
  var sun = new THREE.DirectionalLight(0xffffff, 0.55);
  sun.position.set(2, -3, 5);
  scene.add(sun);

  var planar = runs.every(function (r) { return r.kind === 'planar'; });
  var bodies = 0;

  function material(colour, opacity) {
    // Lambert shading: its shaders compile in a fraction of the physically based ones' time, which is most of the
    // time to the first frame where WebGL runs in software.
    return new THREE.MeshLambertMaterial({
      color: colour, transparent: opacity < 1, opacity: opacity,
      side: opacity < 1 ? THREE.DoubleSide : THREE.FrontSide, depthWrite: opacity >= 1
    });
  }

  // A shape of summary.json (docs/output_formats.md): its local pose, then its geometry; capsules and cylinders
  // run along their z axis.
  function makeShape(s, mat) {
    var g = new THREE.Group();
    var r = s.radius || 0, l = s.length || 0;
    var alongZ = new THREE.Matrix4().makeRotationX(Math.PI / 2);
    if (s.shape === 'sphere') {
      g.add(new THREE.Mesh(new THREE.SphereBufferGeometry(r, 24, 16), mat));
    } else if (s.shape === 'capsule') {
      var body = new THREE.CylinderBufferGeometry(r, r, l, 24, 1, true);
      body.applyMatrix(alongZ);
      g.add(new THREE.Mesh(body, mat));
      [-0.5 * l, 0.5 * l].forEach(function (z) {
        var cap = new THREE.Mesh(new THREE.SphereBufferGeometry(r, 24, 12), mat);
        cap.position.set(0, 0, z);
        g.add(cap);
      });
    } else if (s.shape === 'cylinder') {
      var cyl = new THREE.CylinderBufferGeometry(r, r, l, 24);
      cyl.applyMatrix(alongZ);
      g.add(new THREE.Mesh(cyl, mat));
    } else if (s.shape === 'box') {
      g.add(new THREE.Mesh(new THREE.BoxBufferGeometry(s.size[0], s.size[1], s.size[2]), mat));
    } else if (s.shape === 'convex') {
      var v = s.vertices, f = s.faces, pos = new Float32Array(f.length * 3);
      for (var i = 0; i < f.length; ++i) {
        pos[3 * i] = v[3 * f[i]]; pos[3 * i + 1] = v[3 * f[i] + 1]; pos[3 * i + 2] = v[3 * f[i] + 2];
      }
      var hull = new THREE.BufferGeometry();
      hull.setAttribute('position', new THREE.BufferAttribute(pos, 3));
      hull.computeVertexNormals();
      g.add(new THREE.Mesh(hull, mat));
    } else if (s.shape === 'points' || s.shape === 'octree') {
      var cells = s.cells || [], count = cells.length / 4;
      var cube = new THREE.BoxBufferGeometry(1, 1, 1);
      var inst = new THREE.InstancedMesh(cube, mat, Math.max(1, count));
      var m = new THREE.Matrix4();
      for (var c = 0; c < count; ++c) {
        var e = cells[4 * c + 3] + 2 * (s.radius || 0);
        m.makeScale(e, e, e).setPosition(cells[4 * c], cells[4 * c + 1], cells[4 * c + 2]);
        inst.setMatrixAt(c, m);
      }
      inst.count = count;
      g.add(inst);
    }
    g.position.fromArray(s.position);
    g.quaternion.fromArray(s.quaternion);
    g.userData.body = true;
    return g;
  }

  // The visual meshes, decoded once each (base64 float32 positions, uint32 indices) and shared by every run.
  var meshGeometries = {};
  function decode(text, Type) {
    var bin = atob(text), bytes = new Uint8Array(bin.length);
    for (var i = 0; i < bin.length; ++i) bytes[i] = bin.charCodeAt(i);
    return new Type(bytes.buffer);
  }
  function meshParts(key) {
    if (meshGeometries[key]) return meshGeometries[key];
    var m = data.meshes[key];
    meshGeometries[key] = m.parts.map(function (part) {
      var g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(decode(part.positions, Float32Array), 3));
      g.setIndex(new THREE.BufferAttribute(part.indices16 ? decode(part.indices16, Uint16Array)
                                                          : decode(part.indices, Uint32Array), 1));
      g.computeVertexNormals();
      return { geometry: g, colour: part.colour };
    });
    return meshGeometries[key];
  }
  var visualMaterials = {};
  function visualMaterial(rgb) {
    var key = rgb.join(',');
    if (!visualMaterials[key]) {
      visualMaterials[key] = new THREE.MeshLambertMaterial({ color: new THREE.Color(rgb[0], rgb[1], rgb[2]) });
    }
    return visualMaterials[key];
  }
  // A visual element of a URDF robot (summary.json robot.visuals): a mesh in its parts' colours (else the URDF
  // material's, else grey), or a box, cylinder or sphere.
  function makeVisual(v) {
    var g;
    var rgb = v.rgba ? [v.rgba[0], v.rgba[1], v.rgba[2]] : [0.75, 0.75, 0.75];
    if (v.shape === 'mesh') {
      g = new THREE.Group();
      meshParts(v.mesh).forEach(function (part) {
        g.add(new THREE.Mesh(part.geometry, visualMaterial(part.colour || rgb)));
      });
    } else {
      g = makeShape({ shape: v.shape, size: v.size, radius: v.radius, length: v.length, position: [0, 0, 0],
                      quaternion: [0, 0, 0, 1] }, visualMaterial(rgb));
      g.userData.body = false;
    }
    g.position.fromArray(v.position);
    g.quaternion.fromArray(v.quaternion);
    g.userData.visual = true;
    return g;
  }

  function lineOf(points, colour, dashed) {
    var geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.BufferAttribute(new Float32Array(points), 3));
    var mat = dashed ? new THREE.LineDashedMaterial({ color: colour, dashSize: 0.01, gapSize: 0.007 })
                     : new THREE.LineBasicMaterial({ color: colour });
    var line = new THREE.Line(geo, mat);
    if (dashed) line.computeLineDistances();
    return line;
  }

  // The task rows' columns r_x, r_y, r_z (rd_ for the path): planar runs lie in z = 0.
  function pathPoints(series, prefix) {
    var x = series[prefix + 'x'], y = series[prefix + 'y'], z = series[prefix + 'z'];
    if (!x || !y) return [];
    var out = [];
    for (var i = 0; i < x.length; ++i) {
      if (x[i] === null || y[i] === null) continue;
      out.push(x[i], y[i], z && z[i] !== null ? z[i] : 0);
    }
    return out;
  }

  var views = runs.map(function (run, ri) {
    var colour = new THREE.Color(RUN_COLOURS[ri % RUN_COLOURS.length]);
    var group = new THREE.Group();
    scene.add(group);
    var n = run.joint_names.length;
    var linkMat = material(colour, runs.length > 1 ? 0.85 : 1);
    var frames = [];
    for (var j = 0; j < n; ++j) {
      var f = new THREE.Group();
      group.add(f);
      frames.push(f);
    }
    var collision = [], visual = [];
    run.link_shapes.forEach(function (s) {
      var shape = makeShape(s, linkMat);
      frames[s.joint - 1].add(shape);
      collision.push(shape);
      bodies += 1;
    });
    (run.visuals || []).forEach(function (v) {
      var shape = makeVisual(v);
      if (v.joint > 0) frames[v.joint - 1].add(shape); else group.add(shape);  // the base's are in the world
      visual.push(shape);
    });
    // The links as a polyline (base, joint origins, end effector) and the joints as dots.
    var stick = lineOf(new Array(3 * (n + 2)).fill(0), colour.clone().multiplyScalar(0.6), false);
    stick.material.linewidth = 2;
    group.add(stick);
    var scale = 1;
    var dot = new THREE.SphereBufferGeometry(1, 12, 8);
    var dotMat = new THREE.MeshBasicMaterial({ color: colour.clone().multiplyScalar(0.5) });
    var dots = frames.map(function (f) { var d = new THREE.Mesh(dot, dotMat); f.add(d); return d; });
    var tip = new THREE.Mesh(dot, new THREE.MeshBasicMaterial({ color: 0xe02020 }));
    tip.position.fromArray(run.tool);
    frames[n - 1].add(tip);
    // The desired path, and the end effector's trace up to the cursor.
    var path = pathPoints(run.series, 'rd_');
    if (path.length) group.add(lineOf(path, 0x555555, true));
    var tracePoints = pathPoints(run.series, 'r_');
    // One run: its trace in red over the dashed path; several: each in its run's colour.
    var trace = lineOf(tracePoints.length ? tracePoints : [0, 0, 0], runs.length > 1 ? colour : 0xd62728, false);
    group.add(trace);
    // Obstacles: where they are at t (moving ones at p + v t).
    var obstacleMat = material(new THREE.Color(0x8a8f99), 0.45);
    var obstacles = run.obstacles.map(function (o) {
      var mesh = makeShape(o, obstacleMat);
      mesh.userData.p0 = o.position;
      mesh.userData.v = o.velocity || [0, 0, 0];
      group.add(mesh);
      bodies += 1;
      return mesh;
    });
    return { run: run, group: group, frames: frames, stick: stick, dots: dots, tip: tip, trace: trace,
             obstacles: obstacles, n: n, scale: scale, ri: ri, collision: collision, visual: visual };
  });

  // The scene's extent: the joints over all frames, the path and the obstacles.
  var extent = new THREE.Box3();
  runs.forEach(function (run) {
    var n = run.joint_names.length, p = run.frames.poses;
    for (var k = 0; k < p.length; k += 7) extent.expandByPoint(new THREE.Vector3(p[k], p[k + 1], p[k + 2]));
    var e = run.frames.ee;
    for (var i = 0; i < e.length; i += 3) extent.expandByPoint(new THREE.Vector3(e[i], e[i + 1], e[i + 2]));
    extent.expandByPoint(new THREE.Vector3().fromArray(run.base_position || [0, 0, 0]));
    run.obstacles.forEach(function (o) {
      if (o.shape === 'points' || o.shape === 'octree') return;
      extent.expandByPoint(new THREE.Vector3().fromArray(o.position));
    });
    void n;
  });
  var centre = extent.getCenter(new THREE.Vector3());
  var size = Math.max(extent.getSize(new THREE.Vector3()).length(), 0.1);
  views.forEach(function (v) {
    var d = 0.012 * size;
    v.dots.forEach(function (m) { m.scale.set(d, d, d); });
    v.tip.scale.set(1.4 * d, 1.4 * d, 1.4 * d);
  });
  // A floor grid under the robot (in its plane for a planar robot), 10 cm cells.
  var gridSize = Math.max(1, Math.ceil(size * 2));
  var grid = new THREE.GridHelper(gridSize, gridSize * 10, 0xb8bec9, 0xdde1e7);
  grid.rotation.x = Math.PI / 2;
  grid.position.set(Math.round(centre.x * 10) / 10, Math.round(centre.y * 10) / 10, planar ? -0.001 : 0);
  scene.add(grid);
  scene.add(new THREE.AxesHelper(0.1 * Math.max(1, Math.round(size))));

  function resetCamera() {
    controls.target.copy(centre);
    if (planar) {
      camera.position.set(centre.x, centre.y - 1e-3 * size, centre.z + 1.6 * size);
    } else {
      camera.position.copy(centre).add(new THREE.Vector3(1.1, -1.5, 0.8).normalize().multiplyScalar(2.0 * size));
    }
    camera.near = size / 500;
    camera.far = size * 50;
    camera.updateProjectionMatrix();
    controls.update();
    requestRender();
  }
  function planeView() {
    controls.target.copy(centre);
    camera.position.set(centre.x, centre.y - 1e-3 * size, centre.z + 1.6 * size);
    controls.update();
    requestRender();
  }

  // ---- poses at a time ----
  function frameAt(times, t) {  // the last frame at or before t
    var lo = 0, hi = times.length - 1;
    if (t <= times[0]) return 0;
    if (t >= times[hi]) return hi;
    while (hi - lo > 1) {
      var mid = (lo + hi) >> 1;
      if (times[mid] <= t) lo = mid; else hi = mid;
    }
    return lo;
  }
  var qa = new THREE.Quaternion(), qb = new THREE.Quaternion();
  var tipWorld = new THREE.Vector3();
  function pose(view, t) {
    var run = view.run, times = run.frames.t, p = run.frames.poses, n = view.n;
    var k = frameAt(times, t);
    var k2 = Math.min(k + 1, times.length - 1);
    var a = k2 > k && t > times[k] ? Math.min(1, (t - times[k]) / (times[k2] - times[k])) : 0;
    var pts = view.stick.geometry.attributes.position;
    var base = run.base_position || [0, 0, 0];
    pts.setXYZ(0, base[0], base[1], base[2]);
    for (var j = 0; j < n; ++j) {
      var o = 7 * (k * n + j), o2 = 7 * (k2 * n + j), f = view.frames[j];
      f.position.set(p[o] + a * (p[o2] - p[o]), p[o + 1] + a * (p[o2 + 1] - p[o + 1]),
                     p[o + 2] + a * (p[o2 + 2] - p[o + 2]));
      qa.set(p[o + 3], p[o + 4], p[o + 5], p[o + 6]);
      if (a > 0) {
        qb.set(p[o2 + 3], p[o2 + 4], p[o2 + 5], p[o2 + 6]);
        qa.slerp(qb, a);
      }
      f.quaternion.copy(qa);
      f.updateMatrixWorld(true);
      pts.setXYZ(j + 1, f.position.x, f.position.y, f.position.z);
    }
    view.tip.getWorldPosition(tipWorld);
    pts.setXYZ(n + 1, tipWorld.x, tipWorld.y, tipWorld.z);
    pts.needsUpdate = true;
    view.stick.geometry.computeBoundingSphere();
    view.obstacles.forEach(function (m) {
      var p0 = m.userData.p0, v = m.userData.v;
      m.position.set(p0[0] + v[0] * t, p0[1] + v[1] * t, p0[2] + v[2] * t);
    });
    var st = run.series.t;
    view.trace.geometry.setDrawRange(0, frameAt(st, t) + 1);
  }

  // ---- plots ----
  var plotsBox = document.getElementById('plots');
  var jointRun = main;
  var panels = [];
  function jointSeries(run, re) {
    var out = [];
    Object.keys(run.series).forEach(function (name) {
      var m = re.exec(name);
      if (m) out[Number(m[1]) - 1] = name;
    });
    return out.filter(function (x) { return x !== undefined; });
  }
  function colourOfRun(ri) { return RUN_COLOURS[ri % RUN_COLOURS.length]; }
  function colourOfJoint(j) { return JOINT_COLOURS[j % JOINT_COLOURS.length]; }

  // Each panel: its lines (series of a run), its limit lines, and what its legend says.
  function buildPanels() {
    var list = [];
    function scalar(title, unit, column, extra) {
      var lines = [];
      runs.forEach(function (run, ri) {
        if (run.series[column]) {
          // Overlaid runs: the first widest, each later one narrower and drawn over it, so that curves that
          // coincide stay visible side by side.
          lines.push({ run: ri, t: run.series.t, y: run.series[column], colour: colourOfRun(ri), label: run.label,
                       width: runs.length > 1 ? Math.max(0.9, 3.2 - 1.0 * ri) : 1.4 });
        }
      });
      if (!lines.length) return;
      var panel = { title: title, unit: unit, lines: lines, hlines: [], legend: lines.map(function (l) {
        return { colour: l.colour, label: l.label };
      }), value: column };
      if (extra) extra(panel);
      list.push(panel);
    }
    scalar('manipulability w', '', 'manipulability');
    scalar('position error', 'm', 'position_error');
    scalar('orientation error', 'rad', 'orientation_error');
    scalar('smallest obstacle distance', 'm', 'min_obstacle_distance', function (p) {
      runs.forEach(function (run, ri) {
        var d = run.safety_distances.obstacle_avoidance;
        if (d !== undefined) p.hlines.push({ y: d, colour: colourOfRun(ri), label: 'd_s = ' + d + ' m' });
      });
      p.legend = p.legend.concat(p.hlines.map(function (h) { return { colour: h.colour, label: h.label, dash: 1 }; }));
    });
    scalar('smallest self distance', 'm', 'min_self_distance', function (p) {
      runs.forEach(function (run, ri) {
        var d = run.safety_distances.self_collision;
        if (d !== undefined) p.hlines.push({ y: d, colour: colourOfRun(ri), label: 'd_s = ' + d + ' m' });
      });
      p.legend = p.legend.concat(p.hlines.map(function (h) { return { colour: h.colour, label: h.label, dash: 1 }; }));
    });
    scalar('contacts (MuJoCo)', '', 'contacts');
    // The joints of one run (chosen below the scene when there are several).
    var run = runs[jointRun];
    function joints(title, unit, re, lo, hi, constLimits) {
      var names = jointSeries(run, re);
      if (!names.length) return;
      var lines = [], hlines = [];
      names.forEach(function (name, j) {
        lines.push({ run: jointRun, t: run.series.t, y: run.series[name], colour: colourOfJoint(j), label: name });
        if (lo && run.series[lo + (j + 1)]) {
          lines.push({ run: jointRun, t: run.series.t, y: run.series[lo + (j + 1)], colour: colourOfJoint(j),
                       dash: true, thin: true });
        }
        if (hi && run.series[hi + (j + 1)]) {
          lines.push({ run: jointRun, t: run.series.t, y: run.series[hi + (j + 1)], colour: colourOfJoint(j),
                       dash: true, thin: true });
        }
        if (constLimits) {
          var l = run.lower_limits[j], u = run.upper_limits[j];
          if (isFinite(l)) hlines.push({ y: l, colour: colourOfJoint(j) });
          if (isFinite(u)) hlines.push({ y: u, colour: colourOfJoint(j) });
        }
      });
      var legend = names.map(function (name, j) { return { colour: colourOfJoint(j), label: String(j + 1) }; });
      if (lo || constLimits) legend.push({ colour: '#666', label: 'limits', dash: 1 });
      list.push({ title: title + (runs.length > 1 ? ' (' + run.label + ')' : ''), unit: unit, lines: lines,
                  hlines: hlines, legend: legend, joints: names });
    }
    joints('joint angles', 'rad', /^theta_(\d+)$/, null, null, true);
    joints('joint velocities', 'rad/s', /^theta_dot_(\d+)$/, 'vel_lo_', 'vel_hi_', false);
    joints('joint accelerations', 'rad/s\u00b2', /^theta_ddot_(\d+)$/, 'acc_lo_', 'acc_hi_', false);
    joints('joint torques (MuJoCo)', 'N m', /^torque_(\d+)$/, null, null, false);
    return list;
  }

  function niceTicks(lo, hi, count) {
    var span = hi - lo;
    if (!(span > 0)) return [lo];
    var step = Math.pow(10, Math.floor(Math.log10(span / count)));
    var err = span / count / step;
    if (err >= 7.5) step *= 10; else if (err >= 3.5) step *= 5; else if (err >= 1.5) step *= 2;
    var out = [];
    for (var v = Math.ceil(lo / step) * step; v <= hi + 1e-9 * span; v += step) out.push(Math.abs(v) < 1e-12 * span ? 0 : v);
    return out;
  }
  function label(v) {
    var a = Math.abs(v);
    if (a !== 0 && (a < 1e-3 || a >= 1e4)) return v.toExponential(1);
    return String(Number(v.toPrecision(4)));
  }

  function setupPanels() {
    plotsBox.textContent = '';
    panels = buildPanels().map(function (p) {
      var box = document.createElement('div');
      box.className = 'panel';
      var head = document.createElement('div');
      head.className = 'head';
      var name = document.createElement('span');
      name.className = 'name';
      name.textContent = p.title + (p.unit ? ' (' + p.unit + ')' : '');
      var value = document.createElement('span');
      value.className = 'value';
      var legend = document.createElement('span');
      legend.className = 'legend';
      p.legend.forEach(function (l) {
        var item = document.createElement('span');
        var chip = document.createElement('span');
        chip.className = 'chip' + (l.dash ? ' dash' : '');
        chip.style.background = l.colour;
        chip.style.color = l.colour;
        item.appendChild(chip);
        item.appendChild(document.createTextNode(l.label));
        legend.appendChild(item);
      });
      head.appendChild(name);
      head.appendChild(value);
      box.appendChild(head);
      box.appendChild(legend);
      var canvas = document.createElement('canvas');
      box.appendChild(canvas);
      plotsBox.appendChild(box);
      p.canvas = canvas;
      p.valueBox = value;
      p.still = document.createElement('canvas');
      // The y range: every finite value of its lines and limits.
      var lo = Infinity, hi = -Infinity;
      p.lines.forEach(function (l) {
        l.y.forEach(function (y) { if (y !== null && isFinite(y)) { lo = Math.min(lo, y); hi = Math.max(hi, y); } });
      });
      p.hlines.forEach(function (h) { lo = Math.min(lo, h.y); hi = Math.max(hi, h.y); });
      if (!isFinite(lo)) {
        lo = 0; hi = 1;
        var none = document.createElement('span');
        none.className = 'value';
        none.textContent = p.value && /distance/.test(p.value)
          ? 'no pair measured: every pair stayed beyond its influence distance'
          : 'no finite value recorded';
        head.appendChild(none);
      }
      if (hi - lo < 1e-12 * Math.max(1, Math.abs(hi))) { lo -= 0.5 * Math.max(1e-9, Math.abs(lo)); hi += 0.5 * Math.max(1e-9, Math.abs(hi)); }
      var pad = 0.06 * (hi - lo);
      p.y0 = lo - pad; p.y1 = hi + pad;
      function seek(e) {
        var r = canvas.getBoundingClientRect();
        var x = (e.clientX - r.left) / r.width * canvas.width;
        setTime(Math.max(0, Math.min(tEnd, (x - p.left) / (p.width) * tEnd)));
      }
      canvas.addEventListener('mousedown', function (e) { pause(); seek(e); p.dragging = true; });
      canvas.addEventListener('mousemove', function (e) { if (p.dragging && e.buttons) seek(e); });
      window.addEventListener('mouseup', function () { p.dragging = false; });
      return p;
    });
    drawStill();
  }

  // The plots' lines, drawn once per size into an off-screen canvas; the cursor is drawn over a copy of it.
  function drawStill() {
    var dpr = window.devicePixelRatio || 1;
    panels.forEach(function (p) {
      var w = Math.max(200, Math.round(p.canvas.clientWidth * dpr)), h = Math.round(150 * dpr);
      p.canvas.width = w; p.canvas.height = h;
      p.still.width = w; p.still.height = h;
      var g = p.still.getContext('2d');
      g.fillStyle = '#fff';
      g.fillRect(0, 0, w, h);
      var font = Math.round(10 * dpr);
      g.font = font + 'px system-ui, sans-serif';
      var yt = niceTicks(p.y0, p.y1, 4);
      var left = 8 * dpr + Math.max.apply(null, yt.map(function (v) { return g.measureText(label(v)).width; }));
      var right = 8 * dpr, top = 6 * dpr, bottom = 16 * dpr;
      p.left = left; p.width = w - left - right; p.top = top; p.height = h - top - bottom;
      function X(t) { return left + t / (tEnd || 1) * p.width; }
      function Y(y) { return top + (p.y1 - y) / (p.y1 - p.y0) * p.height; }
      p.X = X; p.Y = Y;
      g.strokeStyle = '#e3e6eb'; g.fillStyle = '#555'; g.lineWidth = 1;
      g.textAlign = 'right'; g.textBaseline = 'middle';
      yt.forEach(function (v) {
        g.beginPath(); g.moveTo(left, Y(v)); g.lineTo(w - right, Y(v)); g.stroke();
        g.fillText(label(v), left - 4 * dpr, Y(v));
      });
      g.textAlign = 'center'; g.textBaseline = 'top';
      niceTicks(0, tEnd, 6).forEach(function (v) {
        g.beginPath(); g.moveTo(X(v), top); g.lineTo(X(v), top + p.height); g.stroke();
        g.fillText(label(v) + (v === 0 ? ' s' : ''), X(v), top + p.height + 3 * dpr);
      });
      g.save();
      g.beginPath(); g.rect(left, top, p.width, p.height); g.clip();
      p.hlines.forEach(function (hl) {
        g.strokeStyle = hl.colour; g.lineWidth = dpr; g.setLineDash([4 * dpr, 3 * dpr]);
        g.beginPath(); g.moveTo(left, Y(hl.y)); g.lineTo(left + p.width, Y(hl.y)); g.stroke();
      });
      p.lines.forEach(function (l) {
        g.strokeStyle = l.colour;
        g.lineWidth = (l.thin ? 0.8 : (l.width || 1.4)) * dpr;
        g.setLineDash(l.dash ? [4 * dpr, 3 * dpr] : []);
        g.beginPath();
        var pen = false;
        for (var i = 0; i < l.t.length; ++i) {
          var y = l.y[i];
          if (y === null || !isFinite(y)) { pen = false; continue; }
          if (pen) g.lineTo(X(l.t[i]), Y(y)); else g.moveTo(X(l.t[i]), Y(y));
          pen = true;
        }
        g.stroke();
      });
      g.restore();
      g.strokeStyle = '#99a1ad'; g.setLineDash([]);
      g.strokeRect(left, top, p.width, p.height);
    });
  }

  function valueAt(line, t) {
    var i = frameAt(line.t, t);
    return line.y[i];
  }
  function drawCursor(t) {
    panels.forEach(function (p) {
      var g = p.canvas.getContext('2d');
      g.drawImage(p.still, 0, 0);
      var x = p.X(t);
      g.strokeStyle = '#e02020'; g.lineWidth = 1.2 * (window.devicePixelRatio || 1); g.setLineDash([]);
      g.beginPath(); g.moveTo(x, p.top); g.lineTo(x, p.top + p.height); g.stroke();
      var parts = [];
      p.lines.forEach(function (l) {
        if (l.dash) return;
        var y = valueAt(l, t);
        if (y === null || !isFinite(y)) return;
        g.fillStyle = l.colour;
        g.beginPath(); g.arc(x, p.Y(y), 2.5 * (window.devicePixelRatio || 1), 0, 2 * Math.PI); g.fill();
        if (!p.joints) parts.push((runs.length > 1 ? l.label + ': ' : '') + label(y));
      });
      p.valueBox.textContent = parts.join('   ');
    });
  }

  // ---- the controls ----
  var slider = document.getElementById('slider');
  var timeBox = document.getElementById('time');
  var playButton = document.getElementById('play');
  var speedBox = document.getElementById('speed');
  var readout = document.getElementById('readout');
  slider.max = String(timeline.length - 1);
  var current = 0, playing = false, last = 0, needRender = true, firstFrameMs = null;

  function requestRender() { needRender = true; }
  function setTime(t) {
    current = Math.max(0, Math.min(tEnd, t));
    views.forEach(function (v) { pose(v, current); });
    slider.value = String(frameAt(timeline, current + 1e-12));
    timeBox.textContent = 't = ' + current.toFixed(3) + ' s / ' + tEnd.toFixed(3) + ' s  (frame ' + slider.value +
                          ' of ' + (timeline.length - 1) + ')';
    var lines = views.map(function (v) {
      var s = v.run.series, i = frameAt(s.t, current), parts = [];
      if (s.manipulability) parts.push('w = ' + label(s.manipulability[i]));
      if (s.position_error) parts.push('error = ' + label(s.position_error[i]) + ' m');
      return (views.length > 1 ? v.run.label + ': ' : '') + parts.join(', ');
    });
    readout.textContent = lines.join('\n');
    drawCursor(current);
    requestRender();
  }
  function setFrame(k) {
    k = Math.max(0, Math.min(timeline.length - 1, k | 0));
    setTime(timeline[k]);
    slider.value = String(k);
  }
  function pause() { playing = false; playButton.textContent = 'Play'; }
  function play() {
    if (current >= tEnd) setTime(0);
    playing = true; playButton.textContent = 'Pause'; last = performance.now();
  }
  playButton.addEventListener('click', function () { if (playing) pause(); else play(); });
  slider.addEventListener('input', function () { pause(); setFrame(Number(slider.value)); });
  document.getElementById('prev').addEventListener('click', function () { pause(); setFrame(Number(slider.value) - 1); });
  document.getElementById('next').addEventListener('click', function () { pause(); setFrame(Number(slider.value) + 1); });
  document.getElementById('reset').addEventListener('click', resetCamera);
  var planeButton = document.getElementById('plane');
  planeButton.addEventListener('click', planeView);
  if (!runs.some(function (r) { return r.kind === 'planar'; })) planeButton.title = 'look down onto the xy plane (p)';
  window.addEventListener('keydown', function (e) {
    if (e.target && e.target.tagName === 'SELECT') return;
    if (e.key === ' ') { e.preventDefault(); if (playing) pause(); else play(); }
    else if (e.key === 'ArrowLeft') { pause(); setFrame(Number(slider.value) - 1); }
    else if (e.key === 'ArrowRight') { pause(); setFrame(Number(slider.value) + 1); }
    else if (e.key === 'r') resetCamera();
    else if (e.key === 'p') planeView();
  });
  controls.addEventListener('change', requestRender);

  // Several runs: one check box each (shown or hidden), and which run's joints the plots show.
  var runsBox = document.getElementById('runs');
  var jointSelect = document.getElementById('joint-run');
  if (runs.length > 1) {
    views.forEach(function (v, ri) {
      var l = document.createElement('label');
      var box = document.createElement('input');
      box.type = 'checkbox'; box.checked = true;
      box.addEventListener('change', function () { v.group.visible = box.checked; requestRender(); });
      var chip = document.createElement('span');
      chip.className = 'chip'; chip.style.background = colourOfRun(ri);
      l.appendChild(box); l.appendChild(chip); l.appendChild(document.createTextNode(v.run.label));
      runsBox.appendChild(l);
      var o = document.createElement('option');
      o.value = String(ri); o.textContent = v.run.label;
      jointSelect.appendChild(o);
    });
    jointSelect.value = String(jointRun);
    jointSelect.addEventListener('change', function () {
      jointRun = Number(jointSelect.value); setupPanels(); drawCursor(current);
    });
  } else {
    document.getElementById('joint-run-label').style.display = 'none';
  }
  if (data.notes && data.notes.length) document.getElementById('notes').textContent = data.notes.join('; ');

  // What the robot is drawn as: its visual meshes (a URDF robot's, one run) or its collision shapes (in the run's
  // colour, which tells overlaid runs apart), or both.
  var drawSelect = document.getElementById('draw');
  var anyVisual = views.some(function (v) { return v.visual.length > 0; });
  function showBodies(mode) {
    views.forEach(function (v) {
      v.visual.forEach(function (m) { m.visible = mode !== 'collision'; });
      v.collision.forEach(function (m) { m.visible = mode !== 'visual' || v.visual.length === 0; });
    });
    requestRender();
  }
  if (anyVisual) {
    drawSelect.value = params.draw || (runs.length > 1 ? 'collision' : 'visual');
    drawSelect.addEventListener('change', function () { showBodies(drawSelect.value); });
    showBodies(drawSelect.value);
  } else {
    document.getElementById('draw-label').style.display = 'none';
  }

  function resize() {
    var w = sceneBox.clientWidth, h = sceneBox.clientHeight;
    renderer.setSize(w, h);
    camera.aspect = w / Math.max(1, h);
    camera.updateProjectionMatrix();
    drawStill();
    drawCursor(current);
    requestRender();
  }
  window.addEventListener('resize', resize);

  function render() {
    renderer.render(scene, camera);
    needRender = false;
    if (firstFrameMs === null) {
      firstFrameMs = performance.now();
      document.getElementById('status').textContent = runs.length + (runs.length > 1 ? ' runs, ' : ' run, ') +
        timeline.length + ' frames, ' + bodies + ' bodies; first frame after ' + Math.round(firstFrameMs) + ' ms';
    }
  }
  function loop(now) {
    if (playing) {
      var dt = Math.min(0.1, (now - last) / 1000);
      last = now;
      var t = current + dt * Number(speedBox.value);
      if (t >= tEnd) { t = tEnd; pause(); }
      setTime(t);
    }
    if (needRender) render();
    requestAnimationFrame(loop);
  }

  var sceneBuiltMs = performance.now();
  setupPanels();
  var plotsDrawnMs = performance.now();
  resize();
  resetCamera();
  var posedMs = performance.now();
  setFrame(params.frame !== undefined ? Number(params.frame) : 0);
  render();

  // What a test reads back (docs/viewer.md, "Testing the page"): the scene's bodies, the frame shown, and where
  // each run's end effector is in the scene.
  function state() {
    var count = 0;
    scene.traverse(function (o) { if (o.userData.body) count += 1; });
    var gl = renderer.getContext();
    return {
      errors: errors.slice(), bodies: count, runs: runs.length, frames: timeline.length,
      visuals: views.reduce(function (a, v) { return a + v.visual.length; }, 0),
      frame: Number(slider.value), t: current, first_frame_ms: firstFrameMs, script_start_ms: scriptStartMs,
      scene_built_ms: sceneBuiltMs, plots_drawn_ms: plotsDrawnMs, posed_ms: posedMs,
      webgl: !!gl && !gl.isContextLost(),
      ee: views.map(function (v) { var p = v.tip.getWorldPosition(new THREE.Vector3()); return [p.x, p.y, p.z]; }),
      canvas: [renderer.domElement.width, renderer.domElement.height], plots: panels.length
    };
  }
  window.redresView = { setFrame: setFrame, setTime: setTime, state: state };
  if (params.test !== undefined) {
    var out = document.getElementById('redres-test');
    out.textContent = JSON.stringify(state());
  }
  requestAnimationFrame(loop);
})();
