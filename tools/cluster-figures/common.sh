# Shared by the figure scripts of notes/cluster.md: the binary, a work folder, and the board at
# 256x256 (its region scaled to 256²) at the spp given.
XYLEM=${XYLEM:-$PWD/target/release/xylem}
WORK=${WORK:-$PWD/out/cluster-figures}
ROOT=$PWD
mkdir -p "$WORK"
board256() { # board256 SPP -> path of the scene
  local f="$WORK/board256_$1.toml"
  sed -e 's/^width = 512/width = 256/' -e 's/^height = 384/height = 256/' -e "s/^spp = 16/spp = $1/" \
    -e 's/^x0 = 206$/x0 = 103/' -e 's/^y0 = 160$/y0 = 107/' -e 's/^x1 = 306$/x1 = 153/' -e 's/^y1 = 224$/y1 = 149/' \
    "$ROOT/scenes/sweep_board.toml" > "$f"
  echo "$f"
}
