include ${DIR}/in.base
fix cad all mesh/surface file ${DIR}/${STL} type 1
fix w all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad
run ${N}
fix mv all move/mesh mesh cad linear 0.05 0 0
fix p all print ${EVERY} "S ${s} ${x} ${z} ${vx} ${vz} ${fz}" screen yes
run ${N}
