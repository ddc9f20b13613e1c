import numpy as np, atrous, json, glob, math
from pathlib import Path
from atrous.eval import corpus as Q

def uniform_filter(a,n):
    r=n//2; p=np.pad(a,r,mode='edge'); c=p.cumsum(0).cumsum(1); c=np.pad(c,((1,0),(1,0)))
    H,W=a.shape
    return (c[n:n+H,n:n+W]-c[:H,n:n+W]-c[n:n+H,:W]+c[:H,:W])/(n*n)

rows=[]
for mp in sorted(Path('out/corpus/full').glob('*/*/manifest.json')):
    man=json.loads(mp.read_text()); sd=mp.parent
    if 'frames' in man or man['reference'] not in man['files']: continue
    ref=Q.load_still(sd,man,man['reference'])['color']
    for stem,e in sorted(man['files'].items()):
        if stem==man['reference']: continue
        b=Q.load_still(sd,man,stem)
        kw={k:b[k] for k in ('albedo','normal','depth','position','variance','emission','ids') if k in b and b[k] is not None}
        D=atrous.denoise(b['color'],**kw)
        F=atrous.denoise(b['color'],**kw,method='eaw',sigma_color=1e6)
        o=np.load(f"out/corpus/full/oidn_cache/{man['scene']}_{stem}_fast.npy")
        rel=lambda x:((x-ref)**2/(ref**2+0.01)).mean(-1)
        eD,eF=rel(D),rel(F)
        sD,sF=uniform_filter(eD,9),uniform_filter(eF,9)
        orc=np.where(sF<sD,eF,eD).mean()
        r=dict(s=man['scene'],spp=e['spp'],oidn=rel(o).mean(),D=eD.mean(),F=eF.mean(),orc=orc,frac=(sF<sD).mean())
        rows.append(r); print({k:(round(v,5) if isinstance(v,float) else v) for k,v in r.items()},flush=True)
import collections
g=collections.defaultdict(list)
for r in rows: g[(r['s'][:2],r['spp'])].append(r)
for k,rs in sorted(g.items()):
    print(k,{n:round(math.exp(np.mean([math.log(r[n]/r['oidn']) for r in rs])),3) for n in ('D','F','orc')})
