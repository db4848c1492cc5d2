# fogcl report: the Pareto plot of error against run time, one panel per scene.
# Embedded in the library (report_plot_py.h) and run after plot_common.py's text as `python3 - DIR`:
# reads DIR/report.csv, writes DIR/report.png.
FLOOR = 1e-12  # zero errors are drawn here on the log axis

rows, scenes = read_rows("report.csv")

STYLE = {
    "precise-rgba32f": ("tab:blue", "o"),
    "fast-rgba32f": ("tab:orange", "s"),
    "precise-rgba16f": ("tab:green", "^"),
    "fast-rgba16f": ("tab:red", "v"),
    "scalar-rgba32f": ("tab:gray", "D"),
}


def err(value):
    return clipped_error(value, FLOOR)


cols = min(3, len(scenes))
nrows = (len(scenes) + cols - 1) // cols
fig, axes = plt.subplots(nrows, cols, figsize=(5.2 * cols, 4.0 * nrows), squeeze=False)
for i, scene in enumerate(scenes):
    ax = axes[i // cols][i % cols]
    pts = []
    for r in rows:
        if r["scene"] != scene:
            continue
        t, e, p = float(r["time_ms"]), err(r["max_abs_err_color"]), err(r["p999_abs_err_color"])
        color, marker = STYLE.get(r["variant"], ("black", "x"))
        if e is not None:
            ax.scatter([t], [e], color=color, marker=marker, s=46, label=r["variant"] + " (max)")
            pts.append((t, e))
        if p is not None:
            ax.scatter([t], [p], facecolors="none", edgecolors=color, marker=marker, s=46)
    # Pareto front of (time, max error): nothing else is both faster and more accurate.
    front = pareto_front(pts)
    if len(front) > 1:
        ax.plot([p[0] for p in front], [p[1] for p in front], color="black", lw=0.8, ls="--", zorder=0)
    ax.set_yscale("log")
    ax.set_title(scene, fontsize=10)
    ax.set_xlabel("time [ms] (device; scalar: host)")
    ax.set_ylabel("|color - float64| (filled: max, hollow: p99.9)")
    ax.grid(True, which="both", alpha=0.3)
    ax.set_xlim(left=0)
for j in range(len(scenes), nrows * cols):
    axes[j // cols][j % cols].axis("off")
handles, labels = axes[0][0].get_legend_handles_labels()
fig.legend(handles, labels, loc="lower center", ncol=len(labels), fontsize=9, frameon=False)
fig.suptitle("fogcl: error against run time (dashed: Pareto front)")
fig.tight_layout(rect=(0, 0.05, 1, 0.96))
save_png(fig, "report.png", 110)
