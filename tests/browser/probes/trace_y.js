// The y values of the trace named `name` in the panel `plot`, as plotly drew them (its full
// data: binary arrays decoded), or null while the panel has no such trace.
({ plot, name }) => {
  const div = document.getElementById(plot);
  const t = div && div._fullData ? div._fullData.find((d) => d.name === name) : null;
  return t ? Array.from(t.y, Number) : null;
}
