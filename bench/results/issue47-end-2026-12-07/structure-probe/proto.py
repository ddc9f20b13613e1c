import sys, json, numpy as np
sys.path.insert(0,'/work/wt/still/scripts/corpus')
import hard_cases as H
from atrous.eval import corpus as Q

def lum(x): return 0.2126*x[...,0]+0.7152*x[...,1]+0.0722*x[...,2]

def shift(a, dy, dx):
    h,w=a.shape[:2]
    ys=np.clip(np.arange(h)+dy,0,h-1); xs=np.clip(np.arange(w)+dx,0,w-1)
    return a[ys][:,xs]

def line_means(r, L, nang):
    out=[]
    half=L//2
    for i in range(nang):
        th=np.pi*i/nang
        c,s=np.cos(th),np.sin(th)
        acc=np.zeros_like(r)
        for t in range(-half,half+1):
            acc+=shift(r,int(round(t*s)),int(round(t*c)))
        out.append(acc/L)
    return np.stack(out)   # A x H x W x C

def giveback(noisy, out, L=9, nang=8, z0=2.5, z1=4.0, win=4):
    r=noisy-out
    m=line_means(r,L,nang)
    ml=lum(m)                                   # A x H x W
    k=np.argmax(np.abs(ml),0)
    best=np.take_along_axis(m,k[None,...,None],0)[0]
    s2=H.box_mean(lum(r)**2,win)                # noise variance (conservative: includes signal)
    z=np.abs(lum(best))/np.sqrt(s2/L+1e-12)
    g=np.clip((z-z0)/(z1-z0),0,1)
    return out+g[...,None]*best, g

def rd(p): return Q._stack(Q.read_exr(p),["R","G","B"])
if __name__=="__main__":
    ref=rd('ref/color.exr'); pos=Q._stack(Q.read_exr('ref/position.exr'),["R","G","B"]) if False else None
    
    for s in (4,16):
        noisy=rd(f'r{s}/color.exr'); out=rd(f'd{s}.exr')
        P=Q.read_exr('ref/position.exr'); 
        z=P[[k for k in P if k.endswith('Z') or k=='B'][0]]
        wall=H.box_mean((np.abs(z)<0.01).astype(float),8)>0.999
        for L,z0,z1 in [(9,2.5,4),(7,2.5,4),(11,2.5,4),(9,2,3),(9,3,5)]:
            o2,g=giveback(noisy,out,L=L,z0=z0,z1=z1)
            print(s,L,z0,z1,'contrast',round(H.stripe_contrast(out,ref,wall),3),'->',round(H.stripe_contrast(o2,ref,wall),3),
                  'relmse',round(Q.relmse(out,ref),5),'->',round(Q.relmse(o2,ref),5),'noisy',round(Q.relmse(noisy,ref),5),'gate mean',round(g.mean(),3))
