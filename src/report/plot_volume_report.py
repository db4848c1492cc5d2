# fogcl report --volumetric: the Pareto plot of error against run time, one panel per scene, and
# the Riemann sum against the physical integrator on the dense scene.
# Embedded in the library (volume_report_plot_py.h) and run after plot_common.py's text as
# `python3 - DIR`: reads DIR/volume-report.csv, writes DIR/volume-report.png.
FLOOR = 1e-9  # zero errors are drawn here on the log axis

rows, scenes = read_rows("volume-report.csv")

# Colour: resolution and upsampling; marker: integrator; filled: rgba32f, hollow: rgba16f.
COLOR = {
    ("full", "depth-aware"): "tab:blue",
    ("half", "depth-aware"): "tab:orange",
    ("half", "bilinear"): "gold",
    ("quarter", "depth-aware"): "tab:green",
    ("quarter", "bilinear"): "yellowgreen",
}
MARKER = {"stylized": "o", "physical": "^", "riemann": "x"}
FRONT = {"stylized": "black", "physical": "tab:red"}


def err(value):
    return clipped_error(value, FLOOR)


def label_of(r):
    res = r["resolution"] + ("" if r["resolution"] == "full" else " " + r["upsampling"])
    return res


panels = scenes + (["dense: riemann vs physical"] if any(r["integrator"] == "riemann" for r in rows) else [])
cols = min(3, len(panels))
nrows = (len(panels) + cols - 1) // cols
# One panel (a report of one scene) is drawn wider, so that the title and the legend fit.
fig, axes = plt.subplots(nrows, cols, figsize=(max(5.4 * cols, 8.6), 4.3 * nrows), squeeze=False)
legend = {}
for i, scene in enumerate(scenes):
    ax = axes[i // cols][i % cols]
    fronts = {}
    for r in rows:
        if r["scene"] != scene or r["integrator"] == "riemann":
            continue
        t, e = float(r["time_ms"]), err(r["max_abs_err"])
        if e is None or t <= 0:
            continue
        color = COLOR.get((r["resolution"], r["upsampling"]), "gray")
        marker = MARKER.get(r["integrator"], "s")
        filled = r["storage"] == "rgba32f"
        h = ax.scatter([t], [e], s=18, marker=marker, alpha=0.75, linewidths=0.8,
                       facecolors=color if filled else "none", edgecolors=color)
        legend.setdefault(label_of(r), h)
        fronts.setdefault(r["integrator"], []).append((t, e))
    for integrator, pts in fronts.items():
        front = pareto_front(pts)
        if len(front) > 1:
            h, = ax.plot([p[0] for p in front], [p[1] for p in front], color=FRONT.get(integrator, "gray"),
                         lw=0.9, ls="--", zorder=0)
            legend.setdefault("Pareto front, " + integrator + " (" + MARKER[integrator] + ")", h)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_title(scene, fontsize=10)
    ax.set_xlabel("device time [ms]")
    ax.set_ylabel("max |color - float64 4096 steps|")
    ax.grid(True, which="both", alpha=0.3)

if len(panels) > len(scenes):
    ax = axes[len(scenes) // cols][len(scenes) % cols]
    for integrator in ("physical", "riemann"):
        pts = sorted((int(r["steps"]), err(r["max_abs_err"])) for r in rows
                     if r["scene"] == "dense" and r["integrator"] == integrator and r["resolution"] == "full"
                     and r["noise"] == "buffer" and r["storage"] == "rgba32f")
        pts = [p for p in pts if p[1] is not None]
        if pts:
            ax.plot([p[0] for p in pts], [p[1] for p in pts], marker=MARKER[integrator],
                    color="tab:red" if integrator == "physical" else "tab:purple",
                    label=integrator + (" (exact segment weight)" if integrator == "physical" else " (textbook sum)"))
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_title("dense (sigma_t x diameter = 50): riemann vs physical", fontsize=10)
    ax.set_xlabel("steps (full resolution, rgba32f)")
    ax.set_ylabel("max |color - float64 4096 steps|")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
# What --max-error sees: per quality variant, the worst max error over the scenes against the sum
# of their times (rgba32f), and the fastest variant meeting each budget on its Pareto front.
if len(panels) < nrows * cols:
    ax = axes[len(panels) // cols][len(panels) % cols]
    panels.append("budget")
    for integrator in ("stylized", "physical"):
        agg = {}
        for r in rows:
            if r["integrator"] != integrator or r["storage"] != "rgba32f":
                continue
            key = (r["steps"], r["resolution"], r["upsampling"], r["noise"])
            e = err(r["max_abs_err"])
            worst, total = agg.get(key, (0.0, 0.0))
            agg[key] = (max(worst, e if e is not None else float("inf")), total + float(r["time_ms"]))
        pts = []
        for (steps, res, up, noise), (e, t) in agg.items():
            color = COLOR.get((res, up), "gray")
            ax.scatter([t], [e], s=18, marker=MARKER[integrator], color=color, alpha=0.75)
            pts.append((t, e))
        front = pareto_front(pts)
        if len(front) > 1:
            ax.plot([p[0] for p in front], [p[1] for p in front], color=FRONT[integrator], lw=0.9, ls="--", zorder=0)
    ax.set_xscale("log")
    ax.set_yscale("log")
    # The marched fog's scenes (physical rows only) are in it when the report ran them: then the
    # physical points are --height-volumetric's budget.
    ax.set_title("what --max-error sees: worst over the scenes (rgba32f)", fontsize=10)
    ax.set_xlabel("device time, sum over the scenes [ms]")
    ax.set_ylabel("worst max |color - float64|")
    ax.grid(True, which="both", alpha=0.3)
for j in range(len(panels), nrows * cols):
    axes[j // cols][j % cols].axis("off")
fig.legend(list(legend.values()), list(legend.keys()), loc="lower center", ncol=4 if cols > 1 else 3, fontsize=8,
           frameon=False)
fig.suptitle("fogcl volumetric pass: error against run time (filled: rgba32f, hollow: rgba16f)")
fig.tight_layout(rect=(0, 0.07 if nrows > 1 or cols > 1 else 0.14, 1, 0.96))
save_png(fig, "volume-report.png", 100)
