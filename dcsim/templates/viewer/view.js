// The player of dcsim's run viewer: draws the scene that dcsim.viewer.scene describes with
// plotly.js and moves it frame by frame (slider, play/pause, speed, view).
(function () {
  "use strict";

  const scene = JSON.parse(document.getElementById("dcsim-scene").textContent);
  const times = scene.times;
  const last = times.length - 1;
  const plot = document.getElementById("plot");
  const slider = document.getElementById("slider");
  const clock = document.getElementById("clock");
  const playButton = document.getElementById("play");
  const speedSelect = document.getElementById("speed");
  const viewSelect = document.getElementById("view");

  // Rotate v by the unit quaternion q = [x, y, z, w].
  function rotate(q, v) {
    const x = q[0], y = q[1], z = q[2], w = q[3];
    const tx = 2 * (y * v[2] - z * v[1]);
    const ty = 2 * (z * v[0] - x * v[2]);
    const tz = 2 * (x * v[1] - y * v[0]);
    return [
      v[0] + w * tx + (y * tz - z * ty),
      v[1] + w * ty + (z * tx - x * tz),
      v[2] + w * tz + (x * ty - y * tx),
    ];
  }

  function columns(points) {
    const x = [], y = [], z = [];
    for (const p of points) {
      x.push(p[0]);
      y.push(p[1]);
      z.push(p[2]);
    }
    return { x: x, y: y, z: z };
  }

  // The members of a body group shown at frame f, as one mesh and its labels (above each).
  function placeBodies(group, f) {
    const mesh = { x: [], y: [], z: [], i: [], j: [], k: [] };
    const labels = { x: [], y: [], z: [], text: [] };
    for (const member of group.members) {
      if (member.hidden && member.hidden[f]) continue;
      const p = member.positions[f];
      const q = member.turns ? member.turns[f] : null;
      const base = mesh.x.length;
      for (const v of member.vertices) {
        const r = q ? rotate(q, v) : v;
        mesh.x.push(r[0] + p[0]);
        mesh.y.push(r[1] + p[1]);
        mesh.z.push(r[2] + p[2]);
      }
      for (const t of member.triangles) {
        mesh.i.push(t[0] + base);
        mesh.j.push(t[1] + base);
        mesh.k.push(t[2] + base);
      }
      labels.x.push(p[0]);
      labels.y.push(p[1]);
      labels.z.push(p[2] + member.lift);
      labels.text.push(member.label);
    }
    return { mesh: mesh, labels: labels };
  }

  // Plumes of the thrusters firing at frame f: from each against its force, turning with
  // the base, longer the more it fired; separated by gaps (null points).
  function plumes(thrusters, robot, f) {
    const p = robot.positions[f];
    const q = robot.turns ? robot.turns[f] : [0, 0, 0, 1];
    const points = [];
    thrusters.duty[f].forEach(function (duty, n) {
      if (!(duty > 0)) return;
      const length = thrusters.length[0] + thrusters.length[1] * duty;
      const at = thrusters.positions[n];
      const d = thrusters.directions[n];
      const tip = [at[0] - length * d[0], at[1] - length * d[1], at[2] - length * d[2]];
      for (const v of [rotate(q, at), rotate(q, tip)]) {
        points.push([p[0] + v[0], p[1] + v[1], p[2] + v[2]]);
      }
      points.push([null, null, null]);
    });
    return points;
  }

  function stageAt(stages, t) {
    let shown = null;
    for (const stage of stages) {
      if (stage.t <= t) shown = stage;
    }
    return shown ? shown.points : [];
  }

  // Every trace, and for each moving one how to draw it at frame f.
  const data = [];
  const updates = [];
  for (const trace of scene.static) data.push(trace);
  for (const group of scene.bodies) {
    const cache = { f: -1, placed: null };
    const placed = function (f) {
      if (cache.f !== f) {
        cache.placed = placeBodies(group, f);
        cache.f = f;
      }
      return cache.placed;
    };
    updates.push({ index: data.length, at: function (f) { return placed(f).mesh; } });
    data.push(Object.assign({}, group.trace));
    if (group.labels) {
      updates.push({ index: data.length, at: function (f) { return placed(f).labels; } });
      data.push({
        type: "scatter3d",
        mode: "markers+text",
        name: group.trace.name + " labels",
        legendgroup: group.trace.legendgroup,
        showlegend: false,
        marker: { color: group.trace.color, size: 3 },
        textfont: { color: group.trace.color, size: 11 },
        textposition: "top center",
        hoverinfo: "text",
      });
    }
  }
  for (const line of scene.polylines) {
    updates.push({ index: data.length, at: function (f) { return columns(line.frames[f]); } });
    data.push(Object.assign({}, line.trace));
  }
  if (scene.thrusters) {
    const robot = scene.bodies.find(function (g) { return g.trace.name === "robot"; }).members[0];
    updates.push({
      index: data.length,
      at: function (f) { return columns(plumes(scene.thrusters, robot, f)); },
    });
    data.push(Object.assign({}, scene.thrusters.trace));
  }
  for (const trail of scene.trails) {
    updates.push({
      index: data.length,
      at: function (f) { return columns(trail.points.slice(0, f + 1)); },
    });
    data.push(Object.assign({}, trail.trace));
  }
  for (const staged of scene.stages) {
    updates.push({
      index: data.length,
      at: function (f) { return columns(stageAt(staged.stages, times[f])); },
    });
    data.push(Object.assign({}, staged.trace));
  }

  // Where the camera starts, relative to the scene box's centre (plotly's default is 1.25 each).
  const CAMERA_EYE = { x: 1.1, y: 1.1, z: 0.75 };

  // The box a view shows at frame f, and the scene's axes for it.
  function viewBox(f) {
    const view = viewSelect.value;
    if (view === "follow") {
      const p = robotPosition(f);
      const h = scene.extent.closeup;
      return [[p[0] - h, p[1] - h, p[2] - h], [p[0] + h, p[1] + h, p[2] + h]];
    }
    return view === "scene" ? scene.extent.scene : scene.extent.work;
  }

  function robotPosition(f) {
    const robot = scene.bodies.find(function (g) { return g.trace.name === "robot"; });
    return robot.members[0].positions[f];
  }

  function sceneLayout(f) {
    const box = viewBox(f);
    const sizes = [0, 1, 2].map(function (a) { return box[1][a] - box[0][a]; });
    const largest = Math.max.apply(null, sizes);
    const axis = function (a, name) {
      return {
        title: { text: name + " [m]" },
        range: [box[0][a], box[1][a]],
        autorange: false,
        backgroundcolor: "#f7f7f7",
        showbackground: true,
      };
    };
    return {
      xaxis: axis(0, scene.axes[0]),
      yaxis: axis(1, scene.axes[1]),
      zaxis: axis(2, scene.axes[2]),
      aspectmode: "manual",
      aspectratio: { x: sizes[0] / largest, y: sizes[1] / largest, z: sizes[2] / largest },
    };
  }

  const layout = {
    margin: { l: 0, r: 0, t: 0, b: 0 },
    uirevision: "dcsim",
    showlegend: true,
    legend: { x: 0, y: 1, bgcolor: "rgba(255,255,255,0.75)" },
    scene: Object.assign({ camera: { eye: CAMERA_EYE } }, sceneLayout(0)),
  };

  // Readouts and the event log.
  const readoutCells = scene.readouts.map(function (readout) {
    const row = document.getElementById("readouts").insertRow();
    const head = document.createElement("th");
    head.textContent = readout.label;
    row.appendChild(head);
    return row.insertCell();
  });
  const eventList = document.getElementById("events");
  const eventItems = scene.events.map(function (event) {
    const item = document.createElement("li");
    const stamp = document.createElement("span");
    stamp.className = "t";
    stamp.textContent = event.t.toFixed(1) + " s";
    item.appendChild(stamp);
    item.appendChild(document.createTextNode(event.text));
    item.className = "future";
    eventList.appendChild(item);
    return item;
  });
  let eventsShown = 0;

  function showEvents(t) {
    let count = 0;
    while (count < scene.events.length && scene.events[count].t <= t) count++;
    const low = Math.min(count, eventsShown), high = Math.max(count, eventsShown);
    for (let n = low; n < high; n++) eventItems[n].className = n < count ? "" : "future";
    if (count !== eventsShown && count > 0) {
      const item = eventItems[count - 1];
      eventList.scrollTop = item.offsetTop - eventList.offsetTop - eventList.clientHeight / 2;
    }
    eventsShown = count;
  }

  // Drawing a frame: one plotly.react at a time, the latest frame asked for wins.
  let frame = 0;
  let drawn = -1;
  let drawing = null;
  let wanted = null;

  function draw(f) {
    for (const update of updates) Object.assign(data[update.index], update.at(f));
    if (viewSelect.value === "follow") layout.scene = Object.assign(layout.scene, sceneLayout(f));
    layout.datarevision = f;
    scene.readouts.forEach(function (readout, n) { readoutCells[n].textContent = readout.values[f]; });
    clock.textContent = times[f].toFixed(1) + " s";
    slider.value = String(f);
    showEvents(times[f]);
    return Plotly.react(plot, data, layout);
  }

  function setFrame(f) {
    frame = Math.max(0, Math.min(last, Math.round(f)));
    if (drawing) {
      wanted = frame;
      return drawing;
    }
    const asked = frame;
    drawing = draw(asked).then(function () {
      drawn = asked;
      drawing = null;
      if (wanted !== null) {
        const next = wanted;
        wanted = null;
        return setFrame(next);
      }
    });
    return drawing;
  }

  // Playback: simulated time runs at the chosen speed; the frame is the latest not after it.
  let playing = false;
  let playTime = 0;
  let lastTick = null;

  function frameAt(t) {
    let lo = 0, hi = last;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (times[mid] <= t) lo = mid; else hi = mid - 1;
    }
    return lo;
  }

  function tick(now) {
    if (!playing) return;
    if (lastTick !== null) playTime += ((now - lastTick) / 1000) * Number(speedSelect.value);
    lastTick = now;
    const f = frameAt(playTime);
    if (f !== frame) setFrame(f);
    if (f >= last) {
      pause();
      return;
    }
    requestAnimationFrame(tick);
  }

  function play() {
    if (frame >= last) setFrame(0);
    playing = true;
    playTime = times[frame];
    lastTick = null;
    playButton.textContent = "pause";
    requestAnimationFrame(tick);
  }

  function pause() {
    playing = false;
    playButton.textContent = "play";
  }

  scene.playback.speeds.forEach(function (speed) {
    const option = document.createElement("option");
    option.value = String(speed);
    option.textContent = speed + "\u00d7";
    option.selected = speed === scene.playback.speed;
    speedSelect.appendChild(option);
  });
  slider.max = String(last);
  slider.addEventListener("input", function () {
    pause();
    setFrame(Number(slider.value));
  });
  playButton.addEventListener("click", function () { (playing ? pause : play)(); });
  viewSelect.addEventListener("change", function () {
    layout.scene = Object.assign(layout.scene, sceneLayout(frame));
    setFrame(frame);
  });
  document.addEventListener("keydown", function (event) {
    if (event.target.tagName === "SELECT" || event.target.tagName === "INPUT") return;
    if (event.key === " ") {
      event.preventDefault();
      (playing ? pause : play)();
    } else if (event.key === "ArrowRight" || event.key === "ArrowLeft") {
      pause();
      setFrame(frame + (event.key === "ArrowRight" ? 1 : -1));
    }
  });

  // For scripts driving the page (tests): the frame count, the frame drawn last, a way to
  // show one (its promise resolves once it is drawn).
  window.dcsimView = {
    frames: times.length,
    ready: false,
    frame: function () { return drawn; },
    setFrame: setFrame,
  };
  Plotly.newPlot(plot, data, layout, { responsive: true, displaylogo: false })
    .then(function () { return setFrame(0); })
    .then(function () { window.dcsimView.ready = true; });
})();
