#!/usr/bin/env python3
"""Per-kernel summary of an Nsight Compute CSV (`ncu --csv --page details`, as scripts/gpu-check.sh's
profile step writes it): time summed per kernel name, with the speed-of-light, cache and occupancy
figures of the first launch of each. usage: scripts/ncu_summary.py FILE.csv [...]"""
import csv,sys,io
def mm_val(r,i): return (r[i['Metric Value']], r[i['Metric Unit']])
for f in sys.argv[1:]:
    txt=open(f).read(); txt=txt[txt.index('"ID"'):]
    rows=list(csv.reader(io.StringIO(txt)))
    hdr=rows[0]; i={h:k for k,h in enumerate(hdr)}
    kern={}
    for r in rows[1:]:
        if len(r)<15: continue
        key=(int(r[i['ID']]), r[i['Kernel Name']])
        kern.setdefault(key,{})[r[i['Metric Name']]]=mm_val(r,i)
    print("==",f,len(kern),"kernels")
    tot=0; agg={}
    for (kid,name),mm in sorted(kern.items()):
        d=mm.get('Duration',('0',''))
        dv=float(d[0].replace(',','') or 0)* {'ns':1e-3,'us':1,'usecond':1,'nsecond':1e-3,'msecond':1e3,'ms':1e3}.get(d[1],1)
        tot+=dv
        short=name.split('(')[0][-70:]
        a=agg.setdefault(short,[0,0,mm]); a[0]+=dv; a[1]+=1
    for k,(t,n,mm) in sorted(agg.items(), key=lambda x:-x[1][0]):
        print(f"{t:8.1f}us x{n:2d} {k[:70]:70s} DRAM% {mm.get('DRAM Throughput',('',''))[0]:>6} L1% {mm.get('L1/TEX Cache Throughput',('',''))[0]:>6} SM% {mm.get('Compute (SM) Throughput',('',''))[0]:>6} L1hit {mm.get('L1/TEX Hit Rate',('',''))[0]:>6} L2hit {mm.get('L2 Hit Rate',('',''))[0]:>6} occ {mm.get('Achieved Occupancy',('',''))[0]:>6} regs {mm.get('Registers Per Thread',('',''))[0]}")
    print("total us", round(tot, 1))
