// The m2wr world in three.js (r111, classic scripts): live over a WebSocket from the
// simulator (web:=true), or a replay from M2WR_REPLAY (a recorded run's data, loaded by a
// <script> before this one, so the page opens from file:// too). Frames, scenes and the
// messages are described in pybullet_gazebo/web/server.py, scene.py and frames.py.
// Coordinates are ROS's: x forward, y left, z up, metres.
(function () {
  'use strict';

  var $ = function (id) { return document.getElementById(id); };
  var problemsShown = {};

  function problem(text) {
    if (problemsShown[text]) { return; }
    problemsShown[text] = true;
    var div = document.createElement('div');
    div.textContent = text;
    $('problems').appendChild(div);
  }

  if (typeof THREE === 'undefined') {
    problem('three.js could not be loaded: nothing can be drawn');
    return;
  }
  THREE.Object3D.DefaultUp.set(0, 0, 1);

  // --- the 3D view ---------------------------------------------------------------------
  var renderer;
  try {
    renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  } catch (err) {
    problem('WebGL is not available in this browser (' + err.message + '): the 3D view ' +
            'cannot be drawn; the status line still shows the robots');
  }
  var scene3 = new THREE.Scene();
  scene3.background = new THREE.Color(0xc9d3dc);
  var camera = new THREE.PerspectiveCamera(50, 1, 0.05, 500);
  camera.position.set(-14, -14, 14);
  var controls = null;
  if (renderer) {
    $('view').appendChild(renderer.domElement);
    controls = new THREE.OrbitControls(camera, renderer.domElement);
    controls.target.set(0, 0, 0);
    controls.update();
  }
  // as Gazebo lights a world: a sun from above, slightly to the side, and ambient light
  scene3.add(new THREE.AmbientLight(0xffffff, 0.45));
  var sun = new THREE.DirectionalLight(0xffffff, 0.75);
  sun.position.set(-5, -1, 9);
  scene3.add(sun);

  function resize() {
    var w = window.innerWidth, h = window.innerHeight;
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
    if (renderer) { renderer.setSize(w, h); }
  }
  window.addEventListener('resize', resize);
  resize();

  // --- shapes --------------------------------------------------------------------------
  function setPose(object, pose) {
    object.position.set(pose[0], pose[1], pose[2]);
    object.quaternion.set(pose[3], pose[4], pose[5], pose[6]);
  }

  function material(colour) {
    var c = colour || [0.7, 0.7, 0.7, 1];
    return new THREE.MeshLambertMaterial({
      color: new THREE.Color(c[0], c[1], c[2]), transparent: c[3] < 1, opacity: c[3] });
  }

  // for tests and scripts: what was drawn
  var stats = window.m2wrStats = { meshesLoaded: 0 };

  var loaders = {};
  function loaderFor(url) {
    var ext = (url.split('?')[0].split('.').pop() || '').toLowerCase();
    if (!loaders[ext]) {
      if (ext === 'stl' && THREE.STLLoader) { loaders[ext] = new THREE.STLLoader(); }
      else if (ext === 'obj' && THREE.OBJLoader) { loaders[ext] = new THREE.OBJLoader(); }
      else if (ext === 'dae' && THREE.ColladaLoader) { loaders[ext] = new THREE.ColladaLoader(); }
    }
    return loaders[ext] ? { ext: ext, loader: loaders[ext] } : null;
  }

  function meshFromTriangles(shape) {
    var geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.Float32BufferAttribute(shape.vertices, 3));
    geometry.setIndex(shape.faces);
    geometry.computeVertexNormals();
    return new THREE.Mesh(geometry, material(shape.colour));
  }

  function loadMesh(shape, holder, owner) {
    var scale = shape.scale || [1, 1, 1];
    holder.scale.set(scale[0], scale[1], scale[2]);
    if (shape.vertices && shape.faces) {
      holder.add(meshFromTriangles(shape));
      return;
    }
    var what = owner + ': mesh ' + shape.uri;
    if (!shape.url) { problem(what + ' is not served: not drawn'); return; }
    var found = loaderFor(shape.url);
    if (!found) { problem(what + ': no loader for this format: not drawn'); return; }
    try {
      found.loader.load(shape.url, function (result) {
        var object;
        if (found.ext === 'stl') {
          object = new THREE.Mesh(result, material(shape.colour));
        } else if (found.ext === 'dae') {
          object = result.scene;
          object.quaternion.set(0, 0, 0, 1);   // the loader turns Z-up files Y-up; ours is Z-up
        } else {
          object = result;
        }
        holder.add(object);
        stats.meshesLoaded += 1;
      }, undefined, function () {
        problem(what + ' could not be loaded: not drawn');
      });
    } catch (err) {
      problem(what + ' could not be loaded (' + err.message + '): not drawn');
    }
  }

  function makeShape(shape, owner) {
    var object;
    if (shape.kind === 'box') {
      object = new THREE.Mesh(new THREE.BoxBufferGeometry(shape.size[0], shape.size[1],
                                                          shape.size[2]), material(shape.colour));
    } else if (shape.kind === 'cylinder') {
      var g = new THREE.CylinderBufferGeometry(shape.radius, shape.radius, shape.length, 32);
      g.rotateX(Math.PI / 2);                 // three's cylinders stand on y; SDF's on z
      object = new THREE.Mesh(g, material(shape.colour));
    } else if (shape.kind === 'sphere') {
      object = new THREE.Mesh(new THREE.SphereBufferGeometry(shape.radius, 24, 16),
                              material(shape.colour));
    } else if (shape.kind === 'plane') {
      var size = [Math.min(shape.size[0], 200), Math.min(shape.size[1], 200)];
      object = new THREE.Mesh(new THREE.PlaneBufferGeometry(size[0], size[1]),
                              material(shape.colour));
      // 1 m cells over the middle 20 m (over the whole plane they alias into stripes)
      var cells = Math.min(size[0], size[1], 20);
      var grid = new THREE.GridHelper(cells, cells, 0x9c9c9c, 0xa8a8a8);
      grid.rotation.x = Math.PI / 2;
      grid.position.z = 0.002;
      object.add(grid);
    } else if (shape.kind === 'mesh') {
      object = new THREE.Group();
      loadMesh(shape, object, owner);
    } else {
      problem(owner + ': a ' + shape.kind + ' shape is not drawn');
      return null;
    }
    setPose(object, shape.pose);
    return object;
  }

  // --- the world and the robots ----------------------------------------------------------
  var world = new THREE.Group();
  scene3.add(world);
  var models = {};          // name -> [link group]
  var robots = {};          // name -> {group, links: {name: group}, path, points, rays}
  var worldBox = new THREE.Box3();

  function setScene(scene) {
    world.children.slice().forEach(function (c) { world.remove(c); });
    models = {};
    worldBox.makeEmpty();
    (scene.problems || []).forEach(problem);
    (scene.models || []).forEach(function (model) {
      models[model.name] = model.links.map(function (link) {
        var group = new THREE.Group();
        setPose(group, link.pose);
        link.shapes.forEach(function (shape) {
          var object = makeShape(shape, model.name + '::' + link.name);
          if (object) { group.add(object); }
        });
        world.add(group);
        if (!model.ground) { worldBox.expandByObject(group); }
        return group;
      });
    });
    if (worldBox.isEmpty()) { worldBox.set(new THREE.Vector3(-5, -5, 0), new THREE.Vector3(5, 5, 1)); }
    if (!following) { frameWorld(); }
  }

  function addRobot(robot) {
    removeRobot(robot.name);
    (robot.problems || []).forEach(problem);
    var group = new THREE.Group();
    var links = {};
    Object.keys(robot.links).forEach(function (name) {
      var link = new THREE.Group();
      robot.links[name].forEach(function (shape) {
        var object = makeShape(shape, robot.name + '::' + name);
        if (object) { link.add(object); }
      });
      link.visible = false;                   // until a frame places it
      links[name] = link;
      group.add(link);
    });
    var pathGeometry = new THREE.BufferGeometry();
    var pathArray = new Float32Array(3 * 40000);
    pathGeometry.setAttribute('position', new THREE.BufferAttribute(pathArray, 3));
    pathGeometry.setDrawRange(0, 0);
    var path = new THREE.Line(pathGeometry, new THREE.LineBasicMaterial({ color: 0x1f6fd0 }));
    path.frustumCulled = false;
    var pointsGeometry = new THREE.BufferGeometry();
    pointsGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * 1024), 3));
    pointsGeometry.setDrawRange(0, 0);
    var points = new THREE.Points(pointsGeometry, new THREE.PointsMaterial({ color: 0xe02020, size: 0.08 }));
    points.frustumCulled = false;
    var raysGeometry = new THREE.BufferGeometry();
    raysGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(6 * 1024), 3));
    raysGeometry.setDrawRange(0, 0);
    var rays = new THREE.LineSegments(raysGeometry, new THREE.LineBasicMaterial({
      color: 0x3050ff, transparent: true, opacity: 0.35 }));
    rays.frustumCulled = false;
    scene3.add(group); scene3.add(path); scene3.add(points); scene3.add(rays);
    robots[robot.name] = { group: group, links: links, path: path, pathArray: pathArray,
                           pathCount: 0, points: points, rays: rays, last: null };
  }

  function removeRobot(name) {
    var r = robots[name];
    if (!r) { return; }
    [r.group, r.path, r.points, r.rays].forEach(function (o) { scene3.remove(o); });
    delete robots[name];
  }

  // the path: a line of points [x, y] (z a little above the ground)
  function setPath(name, flat) {
    var r = robots[name];
    if (!r) { return; }
    r.pathCount = 0;
    for (var i = 0; i + 1 < flat.length; i += 2) { pushPath(r, flat[i], flat[i + 1], true); }
    r.path.geometry.attributes.position.needsUpdate = true;
  }

  function pushPath(r, x, y, quiet) {
    var n = r.pathCount, a = r.pathArray;
    if (n > 0) {
      var dx = x - a[3 * n - 3], dy = y - a[3 * n - 2], d = Math.sqrt(dx * dx + dy * dy);
      if (d < 0.01) { return; }
      if (d > 1.0) { n = 0; }                 // teleported (a reset): a new path
    }
    if (n >= a.length / 3) {                  // full: every other point dropped
      for (var k = 0; k < n / 2; k++) {
        a[3 * k] = a[6 * k]; a[3 * k + 1] = a[6 * k + 1]; a[3 * k + 2] = a[6 * k + 2];
      }
      n = Math.floor(n / 2);
    }
    a[3 * n] = x; a[3 * n + 1] = y; a[3 * n + 2] = 0.02;
    r.pathCount = n + 1;
    r.path.geometry.setDrawRange(0, r.pathCount);
    if (!quiet) { r.path.geometry.attributes.position.needsUpdate = true; }
  }

  function setHits(r, hits) {
    var pts = hits ? hits.points : [];
    var n = Math.min(pts.length / 3, 1024);
    var p = r.points.geometry.attributes.position.array;
    var l = r.rays.geometry.attributes.position.array;
    for (var i = 0; i < n; i++) {
      p[3 * i] = pts[3 * i]; p[3 * i + 1] = pts[3 * i + 1]; p[3 * i + 2] = pts[3 * i + 2];
      l[6 * i] = hits.from[0]; l[6 * i + 1] = hits.from[1]; l[6 * i + 2] = hits.from[2];
      l[6 * i + 3] = pts[3 * i]; l[6 * i + 4] = pts[3 * i + 1]; l[6 * i + 5] = pts[3 * i + 2];
    }
    r.points.geometry.setDrawRange(0, n);
    r.points.geometry.attributes.position.needsUpdate = true;
    r.rays.geometry.setDrawRange(0, 2 * n);
    r.rays.geometry.attributes.position.needsUpdate = true;
    r.rays.visible = $('rays').checked;
  }

  // --- frames ------------------------------------------------------------------------------
  var qa = new THREE.Quaternion(), qb = new THREE.Quaternion();
  function lerpPose(object, a, b, alpha) {
    if (!b || alpha <= 0) { setPose(object, a); return; }
    if (alpha >= 1) { setPose(object, b); return; }
    object.position.set(a[0] + (b[0] - a[0]) * alpha, a[1] + (b[1] - a[1]) * alpha,
                        a[2] + (b[2] - a[2]) * alpha);
    qa.set(a[3], a[4], a[5], a[6]); qb.set(b[3], b[4], b[5], b[6]);
    THREE.Quaternion.slerp(qa, qb, object.quaternion, alpha);
  }

  // draws `frame`, its poses moved `alpha` of the way towards `next` (interpolation)
  function drawFrame(frame, next, alpha) {
    if (!frame) { return; }
    Object.keys(frame.models || {}).forEach(function (name) {
      var groups = models[name];
      if (!groups) { return; }
      var to = next && next.models && next.models[name];
      frame.models[name].forEach(function (pose, i) {
        if (groups[i]) { lerpPose(groups[i], pose, to && to[i], alpha); }
      });
    });
    Object.keys(frame.robots || {}).forEach(function (name) {
      var r = robots[name];
      if (!r) { return; }
      var state = frame.robots[name];
      var to = next && next.robots && next.robots[name];
      Object.keys(r.links).forEach(function (link) {
        var pose = state.links[link];
        if (!pose) { return; }
        r.links[link].visible = true;
        lerpPose(r.links[link], pose, to && to.links[link], alpha);
      });
    });
  }

  function hitsOf(frame) {
    Object.keys(robots).forEach(function (name) {
      setHits(robots[name], frame && frame.hits ? frame.hits[name] : null);
    });
  }

  function fmt(v, d) { return ' ' + v.toFixed(d); }

  function showStatus(frame, extra) {
    if (!frame) { return; }
    var rtf = frame.rtf === null || frame.rtf === undefined ? '  -  ' : frame.rtf.toFixed(2);
    $('sim').textContent = 'sim ' + frame.t.toFixed(3) + ' s  RTF ' + rtf +
      (frame.paused ? '  paused' : '  running') + (extra || '');
    var holder = $('robots');
    holder.textContent = '';
    Object.keys(frame.robots || {}).sort().forEach(function (name) {
      var s = frame.robots[name];
      var span = document.createElement('span');
      span.className = 'robot';
      span.setAttribute('data-name', name);
      span.textContent = name + ' x' + fmt(s.pose[0], 3) + ' y' + fmt(s.pose[1], 3) +
        ' yaw' + fmt(s.yaw, 3);
      holder.appendChild(span);
    });
  }

  // --- the camera: follow the first robot, or frame the world (key f toggles) --------------
  var following = true;
  var lastFollowed = null;
  function frameWorld() {
    if (!controls) { return; }
    var centre = worldBox.getCenter(new THREE.Vector3());
    var size = worldBox.getSize(new THREE.Vector3());
    var span = Math.max(size.x, size.y, 4);
    controls.target.copy(centre);
    camera.position.set(centre.x, centre.y - 0.75 * span, centre.z + 1.0 * span);
    controls.update();
    lastFollowed = null;
  }
  function setFollowing(on) {
    following = on;
    $('follow').textContent = on ? 'Frame world' : 'Follow robot';
    if (!on) { frameWorld(); }
  }
  $('follow').addEventListener('click', function () { setFollowing(!following); });
  window.addEventListener('keydown', function (e) {
    if (e.key === 'f' && e.target.tagName !== 'INPUT') { setFollowing(!following); }
  });
  function follow() {
    if (!following || !controls) { return; }
    var names = Object.keys(robots).sort();
    if (!names.length) { return; }
    var r = robots[names[0]];
    var base = null;
    Object.keys(r.links).forEach(function (l) { if (!base && r.links[l].visible) { base = r.links[l]; } });
    if (!base) { return; }
    var p = base.position;
    if (lastFollowed === null) {
      controls.target.set(p.x, p.y, p.z);
      camera.position.set(p.x - 3.0, p.y - 3.0, p.z + 2.8);
    } else {
      var d = new THREE.Vector3(p.x - lastFollowed.x, p.y - lastFollowed.y, p.z - lastFollowed.z);
      controls.target.add(d);
      camera.position.add(d);
    }
    lastFollowed = p.clone();
    controls.update();
  }

  function render() {
    follow();
    if (renderer) { renderer.render(scene3, camera); }
  }

  $('rays').addEventListener('change', function () {
    Object.keys(robots).forEach(function (n) { robots[n].rays.visible = $('rays').checked; });
  });

  // --- live ----------------------------------------------------------------------------------
  function live() {
    var prev = null, cur = null, prevAt = 0, curAt = 0, socket = null, control = false;
    $('live-controls').hidden = false;
    function send(op) {
      if (socket && socket.readyState === WebSocket.OPEN) { socket.send(JSON.stringify({ op: op })); }
    }
    $('pause').addEventListener('click', function () {
      send(cur && cur.paused ? 'play' : 'pause');
    });
    $('step').addEventListener('click', function () { send('step'); });
    $('reset').addEventListener('click', function () { send('reset'); });

    function onFrame(frame) {
      prev = cur; prevAt = curAt;
      cur = frame; curAt = performance.now();
      Object.keys(frame.robots).forEach(function (name) {
        var r = robots[name];
        if (r) { pushPath(r, frame.robots[name].pose[0], frame.robots[name].pose[1]); }
      });
      hitsOf(frame);
      showStatus(frame, '  ' + watchersText());
      $('pause').textContent = frame.paused ? 'Play' : 'Pause';
    }
    function watchersText() { return control ? '' : 'view only'; }

    function onMessage(event) {
      var m;
      try { m = JSON.parse(event.data); } catch (err) { problem('a message from the simulator was not JSON'); return; }
      if (m.type === 'hello') {
        control = m.control;
        ['pause', 'step', 'reset'].forEach(function (id) { $(id).disabled = !control; });
        setScene(m.scene || {});
        Object.keys(robots).forEach(removeRobot);
        Object.keys(m.robots || {}).forEach(function (n) { addRobot(m.robots[n]); });
        Object.keys(m.paths || {}).forEach(function (n) { setPath(n, m.paths[n]); });
        prev = cur = null;
        if (m.frame) { onFrame(m.frame); }
      } else if (m.type === 'robot') {
        addRobot(m.robot);
      } else if (m.type === 'remove') {
        removeRobot(m.name);
      } else if (m.type === 'frame') {
        onFrame(m);
      } else if (m.type === 'error') {
        problem('the simulator: ' + m.text);
      }
    }

    function connect() {
      var url = (location.protocol === 'https:' ? 'wss://' : 'ws://') + location.host + '/ws';
      socket = new WebSocket(url);
      socket.onmessage = onMessage;
      socket.onclose = function () {
        $('sim').textContent = 'no connection to the simulator; trying again...';
        setTimeout(connect, 2000);
      };
    }
    connect();

    (function animate() {
      requestAnimationFrame(animate);
      if (cur) {
        // one frame interval behind: from prev to cur as the next frame is awaited
        var alpha = prev ? (performance.now() - curAt) / Math.max(curAt - prevAt, 1) : 1;
        drawFrame(prev || cur, prev ? cur : null, Math.min(Math.max(alpha, 0), 1));
      }
      render();
    })();
  }

  // --- replay --------------------------------------------------------------------------------
  function replay(data) {
    var frames = data.frames || [];
    $('replay-controls').hidden = false;
    setScene(data.scene || {});
    Object.keys(data.robots || {}).forEach(function (n) { addRobot(data.robots[n]); });
    if (data.title) { document.title = data.title; }
    if (!frames.length) { $('sim').textContent = 'this replay has no frames'; render(); return; }
    var t0 = frames[0].t, t1 = frames[frames.length - 1].t;
    var t = t0, playing = false, lastWall = null, shownIndex = -1;
    // each robot's path, as [t, x, y] from the frames
    var tracks = {};
    frames.forEach(function (f) {
      Object.keys(f.robots || {}).forEach(function (n) {
        (tracks[n] = tracks[n] || []).push([f.t, f.robots[n].pose[0], f.robots[n].pose[1]]);
      });
    });
    function indexAt(time) {       // the last frame at or before `time`
      var lo = 0, hi = frames.length - 1;
      while (lo < hi) {
        var mid = (lo + hi + 1) >> 1;
        if (frames[mid].t <= time) { lo = mid; } else { hi = mid - 1; }
      }
      return lo;
    }
    function show(time) {
      var i = indexAt(time);
      var a = frames[i], b = frames[Math.min(i + 1, frames.length - 1)];
      var alpha = b.t > a.t ? (time - a.t) / (b.t - a.t) : 0;
      drawFrame(a, b, Math.min(Math.max(alpha, 0), 1));
      if (i !== shownIndex) {
        shownIndex = i;
        hitsOf(a);
        Object.keys(tracks).forEach(function (n) {
          var r = robots[n];
          if (!r) { return; }
          r.pathCount = 0;
          var track = tracks[n];
          for (var k = 0; k < track.length && track[k][0] <= a.t; k++) { pushPath(r, track[k][1], track[k][2], true); }
          r.path.geometry.attributes.position.needsUpdate = true;
        });
        var shown = {};
        Object.keys(a).forEach(function (k) { shown[k] = a[k]; });
        shown.t = time - t0;
        shown.paused = !playing;
        shown.rtf = playing ? parseFloat($('speed').value) : null;
        showStatus(shown, '  of ' + (t1 - t0).toFixed(1) + ' s (replay)');
        $('status').setAttribute('data-frame', String(i));
      }
      $('slider').value = String(Math.round(1000 * (time - t0) / Math.max(t1 - t0, 1e-9)));
    }
    $('play').addEventListener('click', function () {
      playing = !playing;
      if (playing && t >= t1) { t = t0; }
      lastWall = null;
      shownIndex = -1;
      $('play').textContent = playing ? 'Pause' : 'Play';
    });
    $('slider').addEventListener('input', function () {
      t = t0 + (t1 - t0) * parseInt($('slider').value, 10) / 1000;
      shownIndex = -1;
    });
    window.m2wrReplay = {        // for tests and scripts: jump to a time, read where it is
      seek: function (time) { t = Math.min(Math.max(time, t0), t1); shownIndex = -1; show(t); },
      end: t1, start: t0
    };
    (function animate(now) {
      requestAnimationFrame(animate);
      if (playing) {
        if (lastWall !== null) { t += (now - lastWall) / 1000 * parseFloat($('speed').value); }
        lastWall = now;
        if (t >= t1) {
          t = t1; playing = false; $('play').textContent = 'Play'; shownIndex = -1;
        }
      }
      show(t);
      render();
    })(performance.now());
  }

  if (typeof M2WR_REPLAY !== 'undefined') { replay(M2WR_REPLAY); } else { live(); }
})();
