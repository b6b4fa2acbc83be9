(function () {
  const d = JSON.parse(document.getElementById("kinedyn-identification").textContent);
  if (!window.Plotly) return;
  for (const key of ["fit", "validation"]) {
    const p = d[key];
    if (!p) continue;
    d.joint_names.forEach((name, j) => {
      const el = document.getElementById(key + "-joint" + (j + 1));
      const traces = [
        {x: p.t, y: p.measured[j], name: "measured", mode: "lines", line: {width: 1.2, color: "#1f77b4"}},
        {x: p.t, y: p.predicted[j], name: "predicted", mode: "lines", line: {width: 1.2, dash: "dash", color: "#ff7f0e"}},
        {x: p.t, y: p.residual[j], name: "residual", mode: "lines", yaxis: "y2", line: {width: 1, color: "#d62728"}},
      ];
      const layout = {
        title: {text: name + ": RMS " + p.rms[j].toPrecision(3) + ", R² " + p.r2[j].toFixed(6), font: {size: 13}, y: 0.98},
        margin: {l: 60, r: 10, t: 50, b: 40}, height: 320, autosize: true,
        legend: {orientation: "h", x: 0, y: 1.0, yanchor: "bottom", font: {size: 11}},
        xaxis: {title: {text: "t [s]"}, anchor: "y2"}, yaxis: {title: {text: "τ [N m]"}, domain: [0.36, 1], anchor: "x"},
        yaxis2: {title: {text: "residual"}, domain: [0, 0.27], anchor: "x"},
      };
      window.Plotly.newPlot(el, traces, layout, {responsive: true, displaylogo: false});
    });
  }
})();
