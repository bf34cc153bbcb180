# fissure diff: identical images pass, different ones fail, bad input has its own exit status.
. "$top_srcdir/tests/lib.sh"

"$FISSURE" -q -o "$tmp/a" -n a --size 64x64 --set mesh.elements=200 --seed 1 voronoi-tile >/dev/null
"$FISSURE" -q -o "$tmp/b" -n b --size 64x64 --set mesh.elements=200 --seed 2 voronoi-tile >/dev/null
"$FISSURE" -q -o "$tmp/c" -n c --size 32x32 --set mesh.elements=200 --seed 1 voronoi-tile >/dev/null

expect_status 0 "an image equals itself" "$FISSURE" diff "$tmp/a/a_basecolor.png" "$tmp/a/a_basecolor.png"
grep -q 'psnr=inf ssim=1.000000 max_diff=0.000000 ok' "$tmp/stdout" && ok "identical: infinite PSNR, SSIM 1" \
    || not_ok "identical: infinite PSNR, SSIM 1 (got $(cat "$tmp/stdout"))"
expect_status 1 "another pattern is over the threshold" "$FISSURE" diff "$tmp/a/a_height.png" "$tmp/b/b_height.png"
expect_status 0 "a loose threshold accepts it" "$FISSURE" diff --min-psnr 0 --min-ssim -1 "$tmp/a/a_height.png" "$tmp/b/b_height.png"
expect_status 65 "different sizes are not comparable" "$FISSURE" diff "$tmp/a/a_height.png" "$tmp/c/c_height.png"
expect_status 65 "different channel counts are not comparable" "$FISSURE" diff "$tmp/a/a_height.png" "$tmp/a/a_normal.png"
expect_status 66 "a missing image exits 66" "$FISSURE" diff "$tmp/a/a_height.png" "$tmp/nothing.png"
printf 'not a png' > "$tmp/bad.png"
expect_status 65 "an undecodable image exits 65" "$FISSURE" diff "$tmp/a/a_height.png" "$tmp/bad.png"
expect_status 64 "one image is a usage error" "$FISSURE" diff "$tmp/a/a_height.png"
expect_status 64 "a bad threshold is a usage error" "$FISSURE" diff --min-ssim 2 "$tmp/a/a_height.png" "$tmp/a/a_height.png"
finish
