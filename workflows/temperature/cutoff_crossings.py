#!/usr/bin/env python3
"""Fraction of 5th-shell pairs of fcc LJ (2.450 at the T = 0 lattice) beyond the cutoff 2.5 in
the frames of elastic.py's strained NVT runs (docs/temperature.md §3).

    cd OUT && cutoff_crossings.py
"""
import numpy as np, sys
def frames(p):
    L=open(p).read().splitlines(); i=0; out=[]
    while i < len(L):
        n=int(L[i+3]); b=[list(map(float,L[i+5+a].split()[:2])) for a in range(3)]
        x=np.array([l.split()[2:5] for l in L[i+9:i+9+n]],float); out.append((np.array([h-l for l,h in b]),x)); i+=9+n
    return out
for T in ("0.05","0.2","0.4"):
  for s in ("xx+","xx-"):
    fr=frames(f"elastic_T_{T}/{s}/frames.dump")
    tot=0; cross=0
    for Lb,x in fr:
        d=x[:,None,:]-x[None,:,:]; d-=Lb*np.round(d/Lb); r=np.sqrt((d**2).sum(-1))
        shell=(r>2.3)&(r<2.6)  # 5th shell (2.45 at e = 0)
        tot+=shell.sum(); cross+=((r>=2.5)&shell).sum()
    print(T, s, f"5th-shell pairs beyond r_c = 2.5: {cross/tot:.3f}")
