#!/usr/bin/env python3
"""tools/sample41/unit_fit.py -- issue 41's design study (docs/sampling.md, "Sampling a chip").

  unit_fit.py UNITS.tsv PAPER CHIP SPP

UNITS.tsv: bench/speed_vs_error's units-conference.tsv (each unit's cycles on the paper's machine and
the golden model's counts); PAPER: the paper machine's run folder of the same frame, or `tsv` to sum
the units per tile; CHIP: the chip's run folder. A unit's cycles on the chip are not in the report,
so they are taken as its paper-machine cycles times its tile's chip / paper ratio (the proxy; the
per-tile ratio's spread is tile_ratio.py's). Prints the correlations of the chip's tile cycles with
the golden counts, the least-squares fits' residual CVs at unit and tile level, the list schedule on
the fit's tile predictions, and the sample sizes a +-1 % interval needs."""
import json, sys, math, statistics as st
def ols(X, y):
    # X rows without intercept; returns coef [b0,b...], residuals
    n=len(y); k=len(X[0]); A=[[1.0]+list(r) for r in X]
    p=k+1; M=[[sum(A[i][a]*A[i][b] for i in range(n)) for b in range(p)] for a in range(p)]
    v=[sum(A[i][a]*y[i] for i in range(n)) for a in range(p)]
    # gaussian elimination
    for c in range(p):
        piv=max(range(c,p), key=lambda r: abs(M[r][c])); M[c],M[piv]=M[piv],M[c]; v[c],v[piv]=v[piv],v[c]
        for r in range(p):
            if r!=c and M[c][c]!=0:
                f=M[r][c]/M[c][c]; M[r]=[a-f*b for a,b in zip(M[r],M[c])]; v[r]-=f*v[c]
    b=[v[i]/M[i][i] for i in range(p)]
    res=[y[i]-sum(b[j]*A[i][j] for j in range(p)) for i in range(n)]
    return b,res
def corr(a,b):
    ma,mb=st.mean(a),st.mean(b); sa=math.sqrt(sum((x-ma)**2 for x in a)); sb=math.sqrt(sum((x-mb)**2 for x in b))
    return sum((x-ma)*(y-mb) for x,y in zip(a,b))/sa/sb
def load_units(path):
    U={}
    for l in open(path):
        if l[0]=='#': continue
        f=l.split(); U[int(f[0])]=(float(f[1]),[float(v) for v in f[3:6]],[float(v) for v in f[6:9]])
    return U
if __name__=='__main__':
    if len(sys.argv) != 5: sys.exit(__doc__)
    units, paper, chip, spp = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
    U=load_units(units); N=len(U)
    P=json.load(open(paper + '/report.json')) if paper!='tsv' else None; C=json.load(open(chip + '/report.json')); T=len(C['tiles']); K=C['chip']['cores']
    pt=[t['cycles'] for t in P['tiles']] if P else [sum(U[t*spp+q][0] for q in range(spp)) for t in range(T)]; ct=[t['cycles'] for t in C['tiles']]
    yu=[U[u][0]*ct[u//spp]/pt[u//spp] for u in range(N)]  # proxy chip unit cycles
    xu=[U[u][1] for u in range(N)]; xp=[U[u][2] for u in range(N)]
    names=['node_steps','leaf_steps','ray_steps']
    xt=[[sum(U[t*spp+q][1][j] for q in range(spp)) for j in range(3)] for t in range(T)]
    print(f'{chip}: N={N} units, T={T} tiles, K={K}')
    m=st.mean(ct); print(f'  chip tile cycles: mean {m:.0f}, CV {st.pstdev(ct)/m*100:.2f} %; paper tile cycles CV {st.pstdev(pt)/st.mean(pt)*100:.2f} %')
    for j in range(3): print(f'  corr(chip tile cycles, tile {names[j]}) {corr(ct,[r[j] for r in xt]):.4f}; paper {corr(pt,[r[j] for r in xt]):.4f}')
    b,res=ols(xt,ct); r2=1-sum(e*e for e in res)/sum((y-m)**2 for y in ct)
    print(f'  tile-level OLS of chip tile cycles on the 3 tile sums: R^2 {r2:.4f}, residual CV {st.pstdev(res)/m*100:.2f} %')
    rel=[e/c for e,c in zip(res,ct)]; mr=st.mean(rel)
    ac=sum((rel[i]-mr)*(rel[i+1]-mr) for i in range(T-1))/sum((v-mr)**2 for v in rel)
    print(f'  lag-1 autocorrelation of the tile fit\'s relative residuals, frame order: {ac:.2f}')
    b2,res2=ols(xt,pt); mp=st.mean(pt)
    print(f'  tile-level OLS of paper tile cycles: residual CV {st.pstdev(res2)/mp*100:.2f} %')
    mu=st.mean(yu); bu,resu=ols(xu,yu); r2u=1-sum(e*e for e in resu)/sum((y-mu)**2 for y in yu)
    print(f'  unit-level (proxy) OLS: R^2 {r2u:.4f}, unit CV {st.pstdev(yu)/mu*100:.2f} %, residual CV {st.pstdev(resu)/mu*100:.2f} %')
    pu=[U[u][0] for u in range(N)]; mpu=st.mean(pu); bp,resp=ols(xu,pu)
    print(f'  unit-level paper OLS: unit CV {st.pstdev(pu)/mpu*100:.2f} %, residual CV {st.pstdev(resp)/mpu*100:.2f} %')
    # tile residual from unit-level fit: sum of unit residuals per tile
    tr=[sum(resu[t*spp+q] for q in range(spp)) for t in range(T)]
    print(f'  unit-level fit summed per tile: tile residual CV {st.pstdev(tr)/m*100:.2f} % (independent units would give {st.pstdev(resu)/mu*100/math.sqrt(spp):.2f} %)')
    # makespan of the list schedule on the population-fit tile predictions
    def ls(c):
        fr=[0]*K
        for x in c:
            k=min(range(K), key=lambda i:(fr[i],i)); fr[k]+=x
        return max(fr)
    pred=[ct[t]-tr[t] for t in range(T)]
    print(f'  makespan: true {C["cycles"]}, list schedule of population-fit tile predictions {ls(pred):.0f} ({(ls(pred)/C["cycles"]-1)*100:+.3f} %); of paper tiles x (sum chip / sum paper): {(ls([p*sum(ct)/sum(pt) for p in pt])/C["cycles"]-1)*100:+.3f} %')
    for E in (0.01,):
        for cv,lab in ((st.pstdev(ct)/m,'tiles, expansion'),(st.pstdev(res)/m,'tiles, regression'),(st.pstdev(yu)/mu,'units, expansion'),(st.pstdev(resu)/mu,'units, regression')):
            n0=(1.96*cv/E)**2; Np = T if lab.startswith('tiles') else N
            print(f'  +-{E*100:.0f} % needs n0=(1.96 CV/E)^2={n0:.0f} {lab} (with the fpc of N={Np}: {n0/(1+n0/Np):.0f})')
