// The report's interactive figures: every .plotly-chart draws the chart its data-chart key
// names from the JSON block #rps-charts; a mode viewer also gets a mode selector and, asked to
// animate, moves its vertices along the chosen mode (undeformed + sin(phase) x the scaled
// displacement; still, the mode at its largest excursion).
// When every chart has drawn, document.body carries data-charts-rendered = their count.
(function () {
  "use strict";
  var charts = JSON.parse(document.getElementById("rps-charts").textContent);
  var config = {responsive: true, displaylogo: false, scrollZoom: false};
  var PERIOD_MS = 1600;  // one oscillation of a mode
  var FRAME_MS = 50;

  function modeViewer(div, chart) {
    // still until asked: a software-rendered WebGL (a headless browser, a remote desktop)
    // spends most of its time on a moving scene
    var state = {mode: 0, playing: false, visible: !("IntersectionObserver" in window)};
    var bar = document.createElement("div");
    bar.className = "mode-controls";
    var select = document.createElement("select");
    select.setAttribute("aria-label", "mode");
    chart.modes.forEach(function (m, i) {
      var option = document.createElement("option");
      option.value = String(i);
      option.textContent = m.label;
      select.appendChild(option);
    });
    var play = document.createElement("button");
    play.type = "button";
    play.textContent = "animate";
    bar.appendChild(select);
    bar.appendChild(play);
    div.parentNode.insertBefore(bar, div);
    var names = Object.keys(chart.traces);
    var indices = names.map(function (n) { return chart.traces[n]; });

    function moved(name, amount) {
      var base = chart.base[name], move = chart.modes[state.mode].moves[name], out = {};
      ["x", "y", "z"].forEach(function (c) {
        var b = base[c], d = move[c], v = new Array(b.length);
        for (var i = 0; i < b.length; i++) { v[i] = b[i] === null ? null : b[i] + amount * d[i]; }
        out[c] = v;
      });
      return out;
    }

    function draw(amount) {
      var update = {x: [], y: [], z: []};
      names.forEach(function (n) {
        var p = moved(n, amount);
        update.x.push(p.x); update.y.push(p.y); update.z.push(p.z);
      });
      return Plotly.restyle(div, update, indices);
    }

    select.addEventListener("change", function () {
      state.mode = Number(select.value);
      var m = chart.modes[state.mode];
      Plotly.restyle(div, {intensity: [m.intensity]}, [chart.traces.solid]);
      Plotly.relayout(div, {"title.text": m.label});
      if (!state.playing) { draw(1); }
    });
    play.addEventListener("click", function () {
      state.playing = !state.playing;
      play.textContent = state.playing ? "pause" : "animate";
      if (!state.playing) { draw(1); }
    });
    if ("IntersectionObserver" in window) {
      new IntersectionObserver(function (entries) {
        state.visible = entries[0].isIntersecting;
      }).observe(div);
    }
    // at most FRAME_MS apart, one draw in flight, and after each draw a rest as long as it
    // took: a software-rendered WebGL (a headless browser, a remote desktop) keeps at least
    // half the time for everything else on the page
    function tick() {
      if (!(state.playing && state.visible)) {
        window.setTimeout(tick, FRAME_MS);
        return;
      }
      var started = performance.now();
      draw(Math.sin(2 * Math.PI * started / PERIOD_MS)).then(drawn, drawn);
      function drawn() {  // plotly renders the scenes on the next frame: count it in
        window.requestAnimationFrame(function () {
          var took = performance.now() - started;
          window.setTimeout(tick, Math.max(FRAME_MS - took, took));
        });
      }
    }
    tick();
  }

  var pending = [];
  document.querySelectorAll(".plotly-chart").forEach(function (div) {
    var chart = charts[div.dataset.chart];
    var drawn = Plotly.newPlot(div, chart.figure.data, chart.figure.layout, config);
    if (chart.modes) {
      drawn = drawn.then(function () { modeViewer(div, chart); });
    }
    pending.push(drawn);
  });
  Promise.all(pending).then(function () {
    document.body.setAttribute("data-charts-rendered", String(pending.length));
  }, function (error) {
    console.error("a chart failed to draw: " + error);
  });
})();
