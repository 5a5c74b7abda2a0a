"""The vocabulary's clustering beside scikit-learn's, on the same segments.

Reads the segment vectors `imitate embed --vectors` wrote (each segment
resampled along its path and flattened, with its label) and the clusters
table `imitate cluster` wrote from the same segments. Learns a clustering
the way a scikit-learn user would: Isomap (8 neighbours, 8 dimensions, as
`embed`'s defaults) then KMeans (10 restarts), k from 2 to 24 chosen by
the best mean silhouette. Prints one Markdown row per learner: k, purity
and adjusted Rand index over the labelled segments, and seconds.

    python vocab_sklearn.py NAME VECTORS.csv CLUSTERS.csv STARTED ENDED

where STARTED and ENDED (seconds) bracket the `imitate` stages.
"""

import sys
import time

import numpy as np
import pandas as pd
from sklearn.cluster import KMeans
from sklearn.manifold import Isomap
from sklearn.metrics import adjusted_rand_score, silhouette_score


def purity(clusters, labels):
    table = pd.crosstab(clusters, labels)
    return table.max(axis=1).sum() / table.values.sum()


def row(corpus, learner, k, clusters, labels, seconds):
    keep = labels != ""
    c, l = clusters[keep], labels[keep]
    print(f"| {corpus} | {learner} | {k} | {purity(c, l):.3f} | {adjusted_rand_score(l, c):.3f} | {seconds:.2f} |")


def main():
    corpus, vectors_path, clusters_path = sys.argv[1:4]
    ours_seconds = float(sys.argv[5]) - float(sys.argv[4])
    vectors = pd.read_csv(vectors_path, keep_default_na=False)
    labels = vectors["label"].astype(str).to_numpy()
    x = vectors.filter(regex=r"^v\d+$").to_numpy(dtype=float)
    ours = pd.read_csv(clusters_path, comment="#", keep_default_na=False)
    assert len(ours) == len(x), "the clusters table and the vectors must come from the same segments"
    row(corpus, "imitate (ST-Isomap, k-means, silhouette)", ours["cluster"].nunique(), ours["cluster"].to_numpy(), labels,
        ours_seconds)

    started = time.perf_counter()
    embedded = Isomap(n_neighbors=8, n_components=8).fit_transform(x)
    best = None
    for k in range(2, min(24, len(x) - 1) + 1):
        clusters = KMeans(n_clusters=k, n_init=10, random_state=1).fit_predict(embedded)
        score = silhouette_score(embedded, clusters)
        if best is None or score > best[0]:
            best = (score, k, clusters)
    seconds = time.perf_counter() - started
    row(corpus, f"scikit-learn {__import__('sklearn').__version__} (Isomap, KMeans, silhouette)", best[1], best[2],
        labels, seconds)


if __name__ == "__main__":
    import warnings

    warnings.filterwarnings("ignore")
    main()
