#!/usr/bin/env bash
# Markdown tables of tools/heldout.sh's runs: ROWS.tsv (one run per row, columns in heldout.sh)
# summarised per scenario, mode and IMU setting as distributions over seeds.
# Usage: tools/heldout_table.sh ROWS.tsv "DEV SEEDS" "HELD-OUT SEEDS"
set -euo pipefail
rows="$1" dev="$2" held="$3"

# summary SET: per scenario/mode/imu: runs, median and min success, runs >= 99 %, median
# 2 cm / 2 deg success, median of the per-run median errors; with the IMU on a body of
# revolution, the median success scored without removing the turn.
summary() {
  awk -F'\t' -v set="$1" '
    function median(list,   n, v, i, j, t) {
      n = split(list, v, " ")
      for (i = 1; i <= n; ++i) for (j = i + 1; j <= n; ++j) if (v[j] + 0 < v[i] + 0) { t = v[i]; v[i] = v[j]; v[j] = t }
      if (n == 0) return "nan"
      return n % 2 ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2
    }
    function minimum(list,   n, v, i, m) {
      n = split(list, v, " "); m = v[1]
      for (i = 2; i <= n; ++i) if (v[i] + 0 < m + 0) m = v[i]
      return m
    }
    $3 == set {
      k = $1 "\t" $4 "\t" $5
      if (!(k in runs)) order[++nk] = k
      runs[k]++; succ[k] = succ[k] " " $6; tight[k] = tight[k] " " $7
      if ($8 != "nan") rot[k] = rot[k] " " $8
      if ($9 != "nan") tra[k] = tra[k] " " $9
      if ($6 >= 99) pass[k]++
      if ($13 != "-") nosym[k] = nosym[k] " " $13
    }
    END {
      for (i = 1; i <= nk; ++i) {
        k = order[i]; split(k, p, "\t")
        printf "| %s | %s | %s | %d | %.1f %% | %.1f %% | %d | %.1f %% | %s | %s | %s |\n", p[1], p[2], p[3], runs[k],
          median(succ[k]), minimum(succ[k]), pass[k] + 0, median(tight[k]),
          (k in rot) ? sprintf("%.2f", median(rot[k])) : "–", (k in tra) ? sprintf("%.1f", median(tra[k])) : "–",
          (k in nosym) ? sprintf("%.1f %%", median(nosym[k])) : "–"
      }
    }' "$rows"
}

header() {
  echo "| scenario | mode | IMU | runs | median success | min | runs >= 99 % | median within 2 cm / 2 deg | rot. err. (deg) | transl. err. (mm) | IMU, turn not removed |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|"
}

echo "## Held-out seeds"
echo
echo "The rule: **parameters are chosen on development seeds only** ($dev; also mockup_walk 11"
echo "and lampshade 13, the seeds issue 19 named, used to diagnose). The held-out seeds"
echo "($held) were never tuned on; every seed is a new draw of the scene (\`epichead sim SCENARIO"
echo "--seed N\` varies background, light, material and contrast, camera path and speed, occluders"
echo "and the object's placement; sim/scenarios/README.md). Success = frames within 5 cm / 5 deg of"
echo "the truth (a frame reported lost fails); the frames in which a cover board hides the whole"
echo "object (the can's second, sim_truth.json's object_hidden_frames) are not scored, since nothing"
echo "can be measured there, while those in which it slides in or out are. Per scenario the distribution"
echo "over seeds: median, minimum and the number of runs with >= 99 %. Errors: medians over seeds of"
echo "each run's median."
echo "Bodies of revolution are scored with the turn about their axis removed (edges cannot show it);"
echo "the last column scores the IMU runs without removing it (the gyro keeps the turn)."
echo "Regenerate: \`tools/heldout.sh\` (part of \`tools/results.sh\`)."
echo
header
summary held
echo
echo "### The IMU never hurts (held-out)"
echo
echo "Per scenario and mode: held-out runs where success with the IMU is at least success without"
echo "it minus 1 point, and the worst difference (IMU on - off, points)."
echo
echo "| scenario | mode | runs IMU on >= off - 1 | worst on - off |"
echo "|---|---|---|---|"
awk -F'\t' '$3 == "held" { k = $1 "\t" $4 "\t" $2; r[k "\t" $5] = $6; keys[$1 "\t" $4] = 1; seeds[k] = 1 }
  END {
    for (s in seeds) { split(s, p, "\t"); g = p[1] "\t" p[2]
      if (!((s "\toff") in r) || !((s "\ton") in r)) continue
      d = r[s "\ton"] - r[s "\toff"]; n[g]++; if (d >= -1) ok[g]++
      if (!(g in worst) || d < worst[g]) worst[g] = d }
    for (g in n) { split(g, p, "\t"); printf "| %s | %s | %d of %d | %+.1f |\n", p[1], p[2], ok[g] + 0, n[g], worst[g] }
  }' "$rows" | sort
echo
echo "### Vision NIS (held-out, IMU on)"
echo
echo "Normalised innovation squared of each vision pose against the filter's prediction (applied"
echo "and gated updates): with honest covariances chi-square with 6 dof, mean 6 and 95 % of the"
echo "values within [1.24, 14.45]. Pooled over the held-out runs of each scenario and mode."
echo
echo "| scenario | mode | updates | mean NIS | within 95 % bounds |"
echo "|---|---|---|---|---|"
awk -F'\t' '$3 == "held" && $5 == "on" && $12 > 0 { k = $1 "\t" $4; n[k] += $12; m[k] += $10 * $12; w[k] += $11 * $12 }
  END { for (k in n) { split(k, p, "\t"); printf "| %s | %s | %d | %.1f | %.1f %% |\n", p[1], p[2], n[k], m[k] / n[k], 100 * w[k] / n[k] } }' "$rows" | sort
echo
echo "### Vision covariance against the truth (held-out)"
echo
echo "Normalised estimation error squared of each vision pose within 5 cm / 5 deg, against the"
echo "covariance the tracker gives the filter (\`score --covariance\`, vision_covariance.csv; the pose"
echo "estimator's own poses, with the IMU too): with honest covariances chi-square with 6 dof (5 for"
echo "a body of revolution, its turn left out), mean 6 (5) and 95 % within its 2.5-97.5 % quantiles."
echo "Pooled over the held-out runs of each scenario, mode and IMU setting."
echo
echo "| scenario | mode | IMU | frames | mean NEES | within 95 % bounds |"
echo "|---|---|---|---|---|---|"
awk -F'\t' '$3 == "held" && $15 > 0 && $16 != "nan" { k = $1 "\t" $4 "\t" $5; n[k] += $15; m[k] += $16 * $15; w[k] += $17 * $15 }
  END { for (k in n) { split(k, p, "\t"); printf "| %s | %s | %s | %d | %.1f | %.1f %% |\n", p[1], p[2], p[3], n[k], m[k] / n[k], 100 * w[k] / n[k] } }' "$rows" | sort
echo
echo "## Development seeds"
echo
header
summary dev
