"""A sweep into a pandas DataFrame: the mechanism's impact period over the
load ratio and the energy (models/sweeps/impact_period.json, 10,000
points), measured against the closed form, summarised by load ratio.

    target/venv/bin/python examples/python/sweep_pandas.py
"""

from pathlib import Path

import pandas as pd

import flicker

SWEEP = Path(__file__).resolve().parents[2] / "models" / "sweeps" / "impact_period.json"


def main():
    frame = pd.DataFrame(flicker.sweep(SWEEP))
    print(f"{len(frame)} points; statuses: {frame['status'].str.split(':').str[0].value_counts().to_dict()}")
    impacting = frame.dropna(subset=["period_error"])
    by_eta = impacting.groupby(pd.cut(impacting["eta"], 5), observed=True)
    print(by_eta[["impact_period", "period_error"]].agg(["mean", "max"]))
    print(f"largest period error against the closed form: {impacting['period_error'].max():.1e}")


if __name__ == "__main__":
    main()
