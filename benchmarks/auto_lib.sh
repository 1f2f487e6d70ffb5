# Shared by compare_auto.sh and hard_cases_auto.sh (source it; needs AUTO_DIR and PEER set).
#   auto_build DIR      compile shared/peers/auto07p/chain.f90 into DIR/chain.exe with the flags of
#                       AUTO's cmds.make, and cd into DIR
#   auto_points FILE    AUTO's labelled points of a b-file (fort.7): "TYPE Fx" per line (BP, LP, UZ, EP)
#   auto_peer ROOT      the harness directory: $AUTO_PEER, else shared/peers/auto07p beside the
#                       checkout ROOT, else beside the main checkout of a worktree under ../wt
auto_build() {
  local fflags opt
  fflags=$(awk -F'= ' '/^FFLAGS /{print $2}' "$AUTO_DIR/cmds/cmds.make")
  opt=$(awk -F'= ' '/^OPT /{print $2}' "$AUTO_DIR/cmds/cmds.make")
  cp "$PEER/chain.f90" "$1/"
  cd "$1"
  gfortran $fflags $opt -c chain.f90 -o chain.o
  gfortran $fflags $opt chain.o -o chain.exe "$AUTO_DIR"/lib/*.o
}
auto_points() {
  awk '$1==0 && $2=="PT" { for(i=1;i<=NF;i++) col[$i]=i; next } $1==0 { next }
       { ty=$3+0; t=""; if (ty==1||ty==6) t="BP"; else if (ty==2||ty==5) t="LP"; else if (ty==-4) t="UZ"; else if (ty==9) t="EP";
         if (t!="") printf "%s %s\n", t, $(col["Fx"]) }' "$1"
}
auto_peer() {
  local d=${AUTO_PEER:-$1/../shared/peers/auto07p}
  [ -d "$d" ] || d=$1/../../shared/peers/auto07p
  echo "$d"
}
