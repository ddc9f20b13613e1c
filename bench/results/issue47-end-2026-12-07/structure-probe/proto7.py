import sys, numpy as np
sys.path.insert(0,'/work/tune'); sys.path.insert(0,'/work/wt/still/scripts/corpus')
from proto import rd, lum
from proto2 import line_taps
import hard_cases as H, atrous, os
NANG=int(os.environ.get('NANG','8')); TRIM=int(os.environ.get('TRIM','0')); CAP=float(os.environ.get('CAP','1e9'))
from atrous.eval import corpus as Q
def planes(d):
    b={k: rd(f'{d}/{k}.exr') for k in ('color','albedo','normal')}
    try: b['emission']=rd(f'{d}/emission.exr')
    except Exception: pass
    return atrous.prepared_planes(b['color'], albedo=b['albedo'], normal=b['normal'], emission=b.get('emission'), method='sure')
def giveback4(pp, out, L=9, nang=8, z0=2.5, z1=4.0, aniso=0.0, nr=None):
    base=(pp['color']*pp['modulation']+pp['emission'])
    r=base-(out if nr is None else nr); rl=lum(r)
    v=lum(pp['variance']*pp['modulation']**2)
    T=np.sort(line_taps(rl,L,nang),axis=1); m=T[:,TRIM:L-TRIM].mean(axis=1)
    k=np.argmax(np.abs(m),0); best=np.take_along_axis(m,k[None],0)[0]
    vl=line_taps(v,L,nang).mean(axis=1); vb=np.take_along_axis(vl,k[None],0)[0]
    z=np.abs(best)/np.sqrt(vb/L+1e-12)
    g=np.clip((z-z0)/(z1-z0),0,1)
    if aniso: 
        perp=np.take_along_axis(m,((k+nang//2)%nang)[None],0)[0]; g=g*(np.abs(best)>aniso*np.abs(perp))
    lo=lum(out); ratio=np.where((lo>1e-6)[...,None], out/np.maximum(lo,1e-6)[...,None], 1.0)
    gb=np.clip(g*best, -CAP*lo, CAP*lo)
    return out+gb[...,None]*ratio, g
P=[(13,3,5,2),(17,3,5,2),(21,3,5,2),(21,3.5,6,2)]
if __name__=="__main__":
    ref=rd('ref/color.exr'); Z=Q.read_exr('ref/position.exr')['B']; wall=H.box_mean((np.abs(Z)<0.01).astype(float),8)>0.999
    for s in (4,16):
        pp=planes(f'nv{s}'); out=rd(f'd{s}.exr'); nr=rd(f'nv{s}/den_nr.exr'); b=Q.relmse(out,ref); res=[]
        for L,z0,z1,a in P:
            o2,g=giveback4(pp,out,L,NANG,z0,z1,a,nr); res.append(f"{Q.relmse(o2,ref)/b:.3f}(c{H.stripe_contrast(o2,ref,wall):.2f},g{g.mean():.2f})")
        print('blinds',s,f"default {b:.4f} c{H.stripe_contrast(out,ref,wall):.2f}"," ".join(res))
    for n in ['cornell','cornell-spheres','sphere-env','window-room']:
        ref=rd(f'o_{n}_ref/color.exr')
        for s in (4,16):
            pp=planes(f'o_{n}_{s}'); out=rd(f'o_{n}_{s}/den.exr'); nr=rd(f'o_{n}_{s}/den_nr.exr'); b=Q.relmse(out,ref); res=[]
            for L,z0,z1,a in P:
                o2,g=giveback4(pp,out,L,NANG,z0,z1,a,nr); res.append(f"{Q.relmse(o2,ref)/b:.3f}(g{g.mean():.2f})")
            print(n,s,f"default {b:.4f}"," ".join(res))
