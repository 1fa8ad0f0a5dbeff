"""Shared helpers for the plot_*.py scripts: load Google Benchmark CSV files and sweep CSVs."""
import csv
import io


def load_gbench(path):
    """Rows of a Google Benchmark --benchmark_out_format=csv file as dicts (the context lines
    before the header are skipped). Numeric fields are floats where they parse."""
    with open(path, newline="") as f:
        text = f.read()
    start = text.find("name,")
    rows = []
    for row in csv.DictReader(io.StringIO(text[start:])):
        out = {}
        for k, v in row.items():
            try:
                out[k] = float(v)
            except (TypeError, ValueError):
                out[k] = v
        rows.append(out)
    return rows


def medians(rows):
    """{benchmark name without the _median suffix: row} for the median aggregate rows."""
    return {r["name"][: -len("_median")]: r for r in rows if str(r["name"]).endswith("_median")}


def load_csv(path):
    """A plain CSV (the sweeps write these) as a list of dicts with floats where they parse."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        for k, v in r.items():
            try:
                r[k] = float(v)
            except (TypeError, ValueError):
                pass
    return rows
